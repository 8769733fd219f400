"""Plugins: a user's plugin from a folder, entry points, trust, configs, core alone."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.plugins import PluginError, resolve
from ecs_tentacles.world import MissingResource, World

GLOW = '''
import numpy as np
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.store import ArrayStore, Field
from ecs_tentacles.system import System


class GlowStore(ArrayStore):
    level = Field()


class Glow(System):
    """Reads creatures' glow settings; writes glow.level (rises by `rate` a second)."""

    name = "glow"
    stage = "animate"
    reads = ("glow.level",)
    writes = ("glow.level",)

    def __init__(self, rate):
        self.rate = rate

    def process(self, world, dt):
        world.resource(GlowStore).level += self.rate * dt


class GlowPlugin(Plugin):
    name = "glow"
    config_schema = {
        "type": "object", "additionalProperties": False,
        "properties": {"rate": {"type": "number", "minimum": 0, "default": 2.0}},
    }
    creature_schema = {"glow": {"type": "number", "minimum": 0, "maximum": 1, "default": 0.5}}
    scene_schema = {"ambient": {"type": "number", "default": 0.1}}

    def resources(self, world):
        return [GlowStore()]

    def stores(self, world):
        return {"glow": world.resource(GlowStore)}

    def build_creature(self, world, creature, spec):
        world.resource(GlowStore).add(level=spec["glow"])

    def build_scene(self, world, scene):
        world.resource(GlowStore).level += scene["ambient"]

    def systems(self):
        return [Glow(self.config["rate"])]
'''


def glow_scene(folder: Path, **config: object) -> Path:
    (folder / "glow.py").write_text(GLOW)
    scene = {
        "version": 1,
        "ambient": 0.25,
        "plugins": {"glow": {"from": "glow.py", **config}},
        "creatures": [
            {"name": "a", "position": [0, 0], "glow": 0.1, "tentacles": {"count": 3, "links": 2}},
            {"name": "b", "position": [1.5, 0], "tentacles": {"count": 3, "links": 2}},
        ],
    }
    path = folder / "scene.json"
    path.write_text(json.dumps(scene))
    return path


def test_a_plugin_from_a_folder_adds_keys_a_store_and_a_system_at_its_stage(
    tmp_path: Path, make_world: Callable[..., World]
) -> None:
    world = make_world(glow_scene(tmp_path, rate=3.0), allow_systems=True)
    np.testing.assert_allclose(
        world.stores["glow"].level, [0.35, 0.75]
    )  # creature keys + scene key
    assert world.schedule.stage_of("glow") == "animate"
    assert world.schedule.names.index("glow") > world.schedule.names.index("physics")
    assert world.plugin("glow").source == "glow.py"
    assert world.schedule["glow"].plugin == "glow"
    world.step(6)
    np.testing.assert_allclose(world.stores["glow"].level, [0.35 + 0.3, 0.75 + 0.3])


def test_a_plugin_from_a_file_needs_permission(tmp_path: Path) -> None:
    path = glow_scene(tmp_path)
    with pytest.raises(SceneError, match=r"plugins\.glow: runs code from 'glow.py'; allow it"):
        World.from_scene(path)


def test_a_plugin_config_is_checked_against_its_own_schema(tmp_path: Path) -> None:
    path = glow_scene(tmp_path, rate=-1, colour="red")
    with pytest.raises(SceneError) as caught:
        World.from_scene(path, allow_systems=True)
    assert caught.value.problems == [
        f"{path}: plugins.glow.colour: unknown key (allowed: rate)",
        f"{path}: plugins.glow.rate: must be >= 0, got -1",
    ]


def test_a_plugin_key_is_unknown_when_the_plugin_is_off(tmp_path: Path) -> None:
    path = glow_scene(tmp_path)
    data = json.loads(path.read_text())
    data["plugins"]["glow"] = False
    with pytest.raises(SceneError, match=r"scene\.ambient: unknown key|ambient: unknown key"):
        World.from_scene(data, scene_dir=tmp_path)


def test_plugins_turned_off_take_their_keys_and_systems_with_them(
    make_world: Callable[..., World],
) -> None:
    scene = {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}}]}
    world = make_world(scene, plugins={"fur": False})
    assert "rig" not in world.schedule and world.get_resource(FurData) is None
    assert not any(name.startswith("fur.") for name in world.stores)
    with pytest.raises(MissingResource, match="no FurData: the 'fur' plugin provides it"):
        world.resource(FurData)
    with pytest.raises(SceneError, match=r"creatures\[0\]\.fur: unknown key"):
        World.from_scene("hedgehog_octopus", plugins={"fur": False, "threats": False})


def test_unknown_and_unmet_plugins_are_refused() -> None:
    with pytest.raises(PluginError, match=r"plugins\.nope: no plugin of that name"):
        resolve({"nope": {}})
    with pytest.raises(PluginError, match=r"plugins\.suckers: needs the 'locomotion' plugin"):
        resolve({"locomotion": False})


def test_a_file_may_not_leave_the_scene_folder(tmp_path: Path) -> None:
    (tmp_path / "glow.py").write_text(GLOW)
    inner = tmp_path / "scenes"
    inner.mkdir()
    scene = {"version": 1, "plugins": {"glow": {"from": "../glow.py"}}}
    with pytest.raises(SceneError, match=r"plugins\.glow: '\.\./glow\.py' leaves the scene's"):
        World.from_scene(scene, scene_dir=inner, allow_systems=True)


def test_installed_plugins_are_found_by_entry_point(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, make_world: Callable[..., World]
) -> None:
    (tmp_path / "glowing.py").write_text(GLOW)
    info = tmp_path / "glowing-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: glowing\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[ecs_tentacles.plugins]\nglow = glowing:GlowPlugin\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    scene = {"version": 1, "plugins": {"glow": {"rate": 1.0}}}
    with pytest.raises(SceneError, match="runs code from 'glowing:GlowPlugin'; allow it"):
        World.from_scene(scene)
    world = make_world(scene, allow_systems=True)
    assert "glow" in world.schedule and world.plugin("glow").source == "glowing:GlowPlugin"


CORE_ALONE = textwrap.dedent(
    """
    import sys
    from ecs_tentacles.world import World
    off = {"locomotion": False, "suckers": False, "threats": False, "fur": False, "clips": False}
    scene = {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}}]}
    with World.from_scene(scene, plugins=off) as world:
        start = world.transforms.pos.copy()
        world.step(30)
        fell = float(start[:, 2].mean() - world.transforms.pos[:, 2].mean())
        print(world.schedule.names, round(fell, 3) >= 0)
        columns = {name: [f.name for f in store.fields()] for name, store in world.stores.items()}
    # the render layer's registries (pure data) are what a plugin's build(app) fills:
    # the terrain plugin, on, adds its panel; nothing of the renderer itself, no pyglet
    registries = ("ecs_tentacles.render", "ecs_tentacles.render.registries")
    loaded = sorted(m for m in sys.modules if m.startswith(("ecs_tentacles.record",
        "ecs_tentacles.locomotion", "ecs_tentacles.fur", "ecs_tentacles.threats",
        "ecs_tentacles.render", "ecs_tentacles.export", "ecs_tentacles.locomotion.systems",
        "ecs_tentacles.fur.systems", "ecs_tentacles.threats.systems", "pyglet",
        "ecs_tentacles.herding", "ecs_tentacles.herding.systems", "filelock", "platformdirs"))
        and m not in registries)
    print(loaded)
    print(sorted(columns.items()))
    """
)


def test_core_runs_without_any_plugin_imported() -> None:
    result = subprocess.run(
        [sys.executable, "-c", CORE_ALONE], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    names, loaded, columns = result.stdout.strip().splitlines()
    assert names == "['physics', 'physics_sync', 'physics_health'] True"
    assert loaded == "[]"
    # core stores hold the body and its physics only: no locomotion, fur or threat column
    assert columns == str(sorted(BODY_COLUMNS.items()))


BODY_COLUMNS = {
    "transforms": ["pos", "quat"],
    "motors": [
        "target", "strength", "damping", "max_torque", "gain", "tentacle_row", "arc", "scale"
    ],
    "suckers": ["link_row", "tentacle_row", "entity", "offset", "attached", "anchor"],
    "creatures": ["entity", "mantle_row", "mantle_radius", "first_tentacle", "tentacles"],
    "tentacles": [
        "creature_row", "base_angle", "first_link", "links", "base_row", "tip_sucker",
        "length", "joint_limit", "rest_pitch",
    ],
}  # fmt: skip


def test_a_failing_system_is_named_with_its_plugin_and_frame(
    tmp_path: Path, make_world: Callable[..., World]
) -> None:
    from ecs_tentacles.system import SystemFailure

    world = make_world(glow_scene(tmp_path), allow_systems=True)
    world.step(3)
    world.schedule["glow"].rate = "fast"  # type: ignore[attr-defined]  # "fast" * dt fails
    with pytest.raises(SystemFailure) as caught:
        world.step(1)
    assert str(caught.value).startswith(
        "system 'glow' (plugin 'glow') failed at frame 3: TypeError"
    )
    assert isinstance(caught.value.__cause__, TypeError) and world.frame == 3


def test_bake_finds_a_plugin_beside_the_scene_from_another_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.cli import main
    from ecs_tentacles.take import Take

    scenes = tmp_path / "scenes"
    scenes.mkdir()
    path = glow_scene(scenes)
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "glow.npz"
    args = ["bake", str(path), "--seconds", "0.1", "--out", str(out), "--quiet"]
    assert main(args) == 2 and not out.exists()  # not allowed
    assert main([*args, "--allow-systems"]) == 0
    assert Take.load(out).frames == 7


def test_a_system_failure_survives_pickling(
    tmp_path: Path, make_world: Callable[..., World]
) -> None:
    """A Ray worker's failure reaches the driver with its message and the user's traceback."""
    import pickle

    from ecs_tentacles.system import SystemFailure

    world = make_world(glow_scene(tmp_path), allow_systems=True)
    world.schedule["glow"].rate = "fast"  # type: ignore[attr-defined]
    with pytest.raises(SystemFailure) as caught:
        world.step(1)
    back = pickle.loads(pickle.dumps(caught.value))
    assert str(back) == str(caught.value) and (back.label, back.frame) == ("glow", 0)
    assert "in process" in back.user_traceback() and "TypeError" in back.user_traceback()


def test_a_plugin_with_a_hook_of_an_earlier_version_is_refused_with_its_new_name(
    tmp_path: Path,
) -> None:
    (tmp_path / "old.py").write_text(
        "from ecs_tentacles.plugin import Plugin\n"
        "class Old(Plugin):\n"
        "    name = 'old'\n"
        "    def export_curves(self, world):\n"
        "        return None\n"
    )
    scene = {"version": 1, "plugins": {"old": {"from": "old.py"}}, "creatures": [{}]}
    with pytest.raises(SceneError) as refused:
        World.from_scene(scene, scene_dir=tmp_path, allow_systems=True)
    assert str(refused.value) == (
        "plugins.old: cannot import 'old.py': TypeError: Old.export_curves: this hook is now"
        " a TakeTracks entry (a TrackSource of kind 'curves'; docs/extending/output-hooks.md)"
    )
