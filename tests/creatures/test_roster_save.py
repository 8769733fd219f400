"""A running world saved as a scene: spawned creatures in, despawned out, same goals."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.creatures.roster_save import heading_deg, roster_scene, save_roster
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.numeric.quaternions import quat_about_z
from ecs_tentacles.world import World


def test_heading_is_the_turn_about_z() -> None:
    for degrees in (-170.0, -30.0, 0.0, 45.0, 179.0):
        assert heading_deg(quat_about_z(np.radians(degrees))) == pytest.approx(degrees)


def test_the_saved_roster_loads_to_the_same_creatures_goals_and_places(tmp_path: Path) -> None:
    scene = {"version": 1, "name": "mine", "creatures": [
        {"name": "a", "position": [0, 0], "goals": [{"position": [0, 2]}]},
        {"name": "b", "position": [5, 0]},
    ]}  # fmt: skip
    with World.from_scene(scene) as world:
        world.step(30)
        c = world.spawn({"name": "c", "tentacles": {"count": 5}}, position=(10, 0), heading_deg=30)
        world.resource(GoalBook).append(c, [10, 3])
        world.resource(GoalBook).append(c, [12, 3])
        world.despawn(world.creature("b"))
        path = save_roster(world, tmp_path / "saved.json")
        text = path.read_text()
        names = [cr.name for _, cr in sorted(world.query(Creature), key=lambda i: i[1].row)]
        with World.from_scene(path) as again:
            assert [cr.name for _, cr in again.query(Creature)] == names == ["a", "c"]
            for name in names:
                here, there = world.creature(name), again.creature(name)
                assert np.allclose(
                    again.resource(GoalBook).positions(there),
                    world.resource(GoalBook).positions(here),
                    atol=1e-6,
                )
                mantle = world.component(here, Transform).pos[:2]
                assert np.allclose(again.component(there, Transform).pos[:2], mantle, atol=1e-5)
            saved = json.loads(text)
            assert saved["name"] == "mine"
            assert saved["creatures"][1]["heading_deg"] == pytest.approx(30.0, abs=2.0)


def test_a_save_that_cannot_be_written_leaves_nothing(tmp_path: Path) -> None:
    with World.from_scene("octopus") as world:
        assert roster_scene(world)["creatures"][0]["name"] == "octopus"
        with pytest.raises(OSError):
            save_roster(world, tmp_path / "no_such_folder" / "x.json")
        assert not (tmp_path / "no_such_folder").exists()


def test_creatures_too_close_to_be_built_at_rest_are_saved_where_they_fit(tmp_path: Path):
    from ecs_tentacles.creatures.roster_save import fit_at_rest
    from ecs_tentacles.scene.defaults import with_defaults
    from ecs_tentacles.scene.load import load_scene

    rock = {"obstacles": [{"shape": "box", "position": [6.0, 0.0, 0.5], "size": [2, 2, 1]}]}
    scene = {"version": 1, "terrain": rock, "creatures": [{"name": "far", "position": [-9, 0]}]}
    with World.from_scene(scene) as world:
        entries = with_defaults({"version": 1, "creatures": [
            {"name": "a", "position": [0.0, 0.0]},
            {"name": "b", "position": [0.4, 0.0]},  # its tentacles through a's at rest
            {"name": "c", "position": [6.5, 0.0]},  # inside the rock
            {"name": "d", "position": [0.0, 8.0]},  # free: stays
        ]})["creatures"]  # fmt: skip
        assert fit_at_rest(world, entries) == 2
        assert entries[0]["position"] == [0.0, 0.0] and entries[3]["position"] == [0.0, 8.0]
        assert np.hypot(entries[1]["position"][0] - 0.4, entries[1]["position"][1]) > 0.3
        saved = {**scene, "creatures": entries}
        load_scene(saved)  # no overlap left: the scene's own check agrees
        with World.from_scene(saved) as again:  # and the terrain's build check
            again.step(5)


PLUGIN = (
    "import pathlib\n"
    "from ecs_tentacles.plugin import Plugin\n"
    "pathlib.Path('{marker}').write_text('ran')\n"
    "class Spawner(Plugin):\n"
    "    name = 'spawner'\n"
)


def test_saving_imports_no_plugin_file_from_the_current_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The world's scene turns on a plugin from a file beside it; a file of that name in
    the folder the sandbox runs in is someone else's code: a save must not run it."""
    scenes, work = tmp_path / "scenes", tmp_path / "work"
    scenes.mkdir()
    work.mkdir()
    (scenes / "spawner.py").write_text(PLUGIN.format(marker=scenes / "loaded.marker"))
    (work / "spawner.py").write_text(PLUGIN.format(marker=work / "hostile.marker"))
    scene = {"version": 1, "plugins": {"spawner": {"from": "spawner.py"}},
             "creatures": [{"name": "a", "position": [0, 0]}]}  # fmt: skip
    (scenes / "mine.json").write_text(json.dumps(scene))
    with World.from_scene(scenes / "mine.json", allow_systems=True) as world:
        assert (scenes / "loaded.marker").exists()  # the scene's own plugin, allowed
        monkeypatch.chdir(work)
        saved = save_roster(world, scenes / "saved.json")
        # saved beside that other file, the scene would run it when loaded: refused
        from ecs_tentacles.scene.errors import SceneError

        with pytest.raises(SceneError, match=r"^plugins\.spawner\.from: .*work/spawner\.py is"):
            save_roster(world, work / "saved.json")
    assert not (work / "hostile.marker").exists()
    assert not (work / "saved.json").exists()
    assert json.loads(saved.read_text())["plugins"]["spawner"] == {"from": "spawner.py"}


TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def _terrain_scene(folder: Path) -> dict:
    """A scene in `folder` naming a 16-bit height image (in a subfolder) and a mesh."""
    from PIL import Image

    (folder / "maps").mkdir()
    pixels = np.zeros((16, 16), dtype=np.uint16)
    pixels[:4, :] = 65535
    Image.fromarray(pixels).save(folder / "maps" / "sixteen.png")
    (folder / "rock.obj").write_text(TETRA)
    return {"version": 1, "name": "shore", "terrain": {
        "heightfield": {"size": [8, 8], "image": "maps/sixteen.png", "height": 0.3},
        "obstacles": [{"shape": "mesh", "file": "rock.obj", "position": [3, 3, 0]}],
    }, "creatures": [{"name": "a", "position": [-2, -2]}]}  # fmt: skip


def test_a_scene_naming_terrain_files_saved_in_another_folder_loads_from_there(
    tmp_path: Path,
) -> None:
    from ecs_tentacles.ground import ground_of

    scenes, other = tmp_path / "scenes", tmp_path / "other"
    scenes.mkdir()
    other.mkdir()
    (scenes / "shore.json").write_text(json.dumps(_terrain_scene(scenes)))
    with World.from_scene(scenes / "shore.json") as world:
        world.step(5)
        saved = save_roster(world, other / "saved.json")
        digest = ground_of(world).digest()
    assert saved == other / "saved.json"
    assert (other / "maps" / "sixteen.png").read_bytes() == (
        scenes / "maps" / "sixteen.png"
    ).read_bytes()
    assert (other / "rock.obj").read_text() == TETRA
    with World.from_scene(saved) as again:  # from its own folder, not the first scene's
        assert ground_of(again).digest() == digest
        assert [c.name for _, c in again.query(Creature)] == ["a"]


def test_a_save_that_would_overwrite_another_file_of_the_same_name_is_refused(
    tmp_path: Path,
) -> None:
    from ecs_tentacles.scene.errors import SceneError

    scenes, other = tmp_path / "scenes", tmp_path / "other"
    scenes.mkdir()
    (other / "maps").mkdir(parents=True)
    (other / "maps" / "sixteen.png").write_bytes(b"someone else's picture")
    (scenes / "shore.json").write_text(json.dumps(_terrain_scene(scenes)))
    with World.from_scene(scenes / "shore.json") as world:
        with pytest.raises(SceneError) as error:
            save_roster(world, other / "saved.json")
    (line,) = str(error.value).splitlines()
    assert line.startswith("terrain.heightfield.image: ")
    assert str(other / "maps" / "sixteen.png") in line
    assert (other / "maps" / "sixteen.png").read_bytes() == b"someone else's picture"
    assert sorted(p.name for p in other.rglob("*")) == ["maps", "sixteen.png"]  # no copy


def test_a_saved_scenes_schema_reference_resolves_from_where_it_is_saved(tmp_path: Path) -> None:
    """The bundled scenes say `"$schema": "../schema/scene.schema.json"`; a save kept it,
    pointing nowhere from the folder it was saved in (editors lost completion)."""
    from importlib.resources import files

    bundled = json.loads(
        (files("ecs_tentacles.assets") / "schema" / "scene.schema.json").read_text()
    )
    for folder in (tmp_path, tmp_path / "deep" / "er"):
        folder.mkdir(parents=True, exist_ok=True)
        with World.from_scene("octopus") as world:
            saved = save_roster(world, folder / "octopus_directed.json")
        reference = json.loads(saved.read_text())["$schema"]
        assert not Path(reference).is_absolute()
        assert json.loads((saved.parent / reference).read_text()) == bundled
