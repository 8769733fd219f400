"""A glb's size counted before any work: never less than the file the writers make and
close to it; a scene and its take's header count alike; a glb past 4 GiB (or a mesh
past 16-bit indices) is refused by `bake` and `export` with one line, exit 2, nothing
written, before the bake builds anything and before export reads a frame."""

from __future__ import annotations

import functools
import json
import os
import subprocess
import sys
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.export.glb import GLB_MAX_BYTES, GlbTooLarge
from ecs_tentacles.export.glb_size import glb_problem, glb_size, shapes_of_header, shapes_of_scene
from ecs_tentacles.export.gltf import write_glb
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.export.skinned_gltf import write_skinned_glb
from ecs_tentacles.record.systems.record import Record
from ecs_tentacles.skin.mesh import Detail
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.take import Take
from ecs_tentacles.world import World

ROOT = Path(__file__).resolve().parents[2]
TERRAIN = {
    "heightfield": {"size": [6, 6], "resolution": 17, "height": 0.3, "noise": {"seed": 2}},
    "obstacles": [{"shape": "box", "position": [1.8, 0, 0.2], "size": [0.4, 1.0, 0.4]}],
}


def _creature(name: str, x: float, **tentacles: Any) -> dict[str, Any]:
    return {"name": name, "position": [x, 0.0], "goals": [{"position": [x, 2.0]}],
            "tentacles": {"count": 3, "links": 3, **tentacles}}  # fmt: skip


@pytest.fixture(scope="module")
def mixed_take() -> Iterator[Take]:
    """Everything a glb holds: terrain, goals, suckers on every link, a tentacle of its
    own, a creature that leaves and one that comes (30 frames)."""
    odd = {"overrides": [{"index": 1, "links": 5, "link_radius": 0.03}]}
    scene = {
        "version": 1,
        "terrain": TERRAIN,
        "creatures": [_creature("a", 0.0, suckers="every_link", **odd), _creature("b", 3.0)],
    }
    with World.from_scene(scene) as world:
        record = world.add_system(Record())
        world.step(10)
        world.despawn(world.creature("b"))
        world.step(10)
        world.spawn(_creature("late_comer", -3.0, count=5))
        world.step(9)
        yield record.take()


FORMS = {
    "rigid": (None, None, True),
    "rigid, no locators": (None, None, False),
    "skinned": (Detail(), Keys(), False),
    "skinned, reduced keys and locators": (Detail(3, 8), Keys("reduced", 0.5), True),
}


@pytest.mark.parametrize("form", FORMS)
def test_the_count_is_never_less_than_the_file_and_close_to_it(
    mixed_take: Take, tmp_path: Path, form: str
) -> None:
    detail, keys, locators = FORMS[form]
    path = tmp_path / "take.glb"
    if detail is None:
        write_glb(mixed_take, path, locators)
    else:
        write_skinned_glb(mixed_take, path, Skin(detail, keys or Keys()), locators)
    size = glb_size(shapes_of_header(mixed_take.header), detail, keys, locators)
    written = path.stat().st_size
    assert written <= size.total() <= 1.35 * written, (written, size.total())
    assert size.total(size.frames) == size.total()
    assert size.total(size.frames + 10) - size.total() == 10 * size.per_frame


def test_a_crowd_counts_within_an_eighth_at_a_second(tmp_path: Path) -> None:
    """6 creatures of several species (varied links and radii, fur), 1 s at 30 fps: the
    JSON, counted at its widest, is as large as a second's keys here."""
    plan = BakePlan.make(crowd_scene(6, seed=1), seconds=1.0, fps=30.0)
    take = bake(plan, progress=False)
    assert shapes_of_scene(plan.scene, plan.frames) == shapes_of_header(take.header)
    for detail in (None, Detail()):
        path = tmp_path / "crowd.glb"
        (write_glb if detail is None else write_skinned_glb)(take, path)
        size = glb_size(shapes_of_scene(plan.scene, plan.frames), detail).total()
        assert path.stat().st_size <= size <= 1.125 * path.stat().st_size


@functools.cache
def _uniform_crowd() -> dict[str, Any]:
    return crowd_scene(1024, seed=3, uniform=True)


@functools.cache  # a plan is frozen, and checking 1,024 creatures costs most of a second
def _uniform_plan(frames: int) -> BakePlan:
    return BakePlan.make(_uniform_crowd(), seconds=(frames - 1) / 60, fps=60.0)


@pytest.mark.parametrize("skin", [None, Skin()])
def test_a_plan_is_refused_one_frame_past_what_a_glb_holds(skin: Skin | None) -> None:
    """The 1,024 crowd (82,944 bodies): the most frames whose glb fits pass, one more is
    refused, naming the size, the limit and what fits."""
    shapes = shapes_of_scene(_uniform_plan(2).scene, 1)
    detail = None if skin is None else skin.detail
    most = glb_size(shapes, detail).most_frames()
    assert (
        glb_size(shapes, detail).total(most)
        <= GLB_MAX_BYTES
        < glb_size(shapes, detail).total(most + 1)
    )
    assert 1000 < most < 4000  # 28 B a body-frame (rigid), 16 B a joint-frame (skinned)
    assert _uniform_plan(most).glb_problem("crowd.glb", skin, None) is None
    problem = _uniform_plan(most + 1).glb_problem("crowd.glb", skin, None)
    assert problem is not None and "\n" not in problem
    form = "rigid" if skin is None else "skinned"
    assert problem.startswith(
        f"crowd.glb: the glb would be up to 4.3 GB (1,024 creatures x {most + 1:,} frames,"
        f" {form}); a glb holds at most 4.3 GB"
    )
    # a take of so many frames is read a chunk at a time: the take and USD fit
    assert problem.endswith(
        f": bake to .usdc or .npz, or fewer frames or creatures (at most {most:,} frames at"
        " this size)"
    )
    assert _uniform_plan(3).glb_problem("crowd.usdc", skin, None) is None  # not a glb


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "ecs_tentacles", *args],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip


def test_bake_refuses_a_glb_too_large_before_building_anything(tmp_path: Path) -> None:
    """1,024 creatures meshed at 16 rings a link, 44 sides: 4.3 MB a creature, so not
    one frame fits; the take would (58 MB), so .usdc and .npz are offered."""
    scene = tmp_path / "crowd.json"
    scene.write_text(json.dumps(_uniform_crowd()))
    done = _run("bake", str(scene), "--seconds", "1", "--fps", "24", "--rings-per-link", "16",
                "--sides", "44", "--out", "crowd.glb", cwd=tmp_path)  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and done.stdout == ""  # one line, no "bake: ..."
    assert done.stderr.startswith("error: crowd.glb: the glb would be up to 4.4 GB (1,024")
    assert "25 frames, skinned); a glb holds at most 4.3 GB" in done.stderr
    assert done.stderr.rstrip().endswith(
        "bake to .usdc or .npz, or fewer creatures or a lighter mesh (--rings-per-link,"
        " --sides: not one frame fits)"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.json"]  # nothing written


def _crowd_take(creatures: int, path: Path) -> None:
    """A real take (2 frames) of `creatures` copies of a creature of 6 tentacles of 10
    links, side by side."""
    scene = {"version": 1, "creatures": [_creature("c", 0.0, count=6, links=10)]}
    with World.from_scene(scene) as world:
        record = world.add_system(Record())
        world.step(1)
        single = record.take()
    header = json.loads(json.dumps(single.header))
    per, entry = len(header["bodies"]), header["creatures"][0]
    new: dict[str, list[Any]] = {"creatures": [], "bodies": [], "suckers": [], "goals": []}
    for c in range(creatures):
        name, first = f"c{c:04d}", c * per

        def renamed(item: dict[str, Any], name: str = name, **more: Any) -> dict[str, Any]:
            return {**item, **more, "name": name + item["name"][1:]}  # c/... -> c0007/...

        chains = [[first + i for i in chain] for chain in entry["tentacles"]]
        new["creatures"].append(renamed(entry, mantle=first + entry["mantle"], tentacles=chains))
        new["bodies"] += [renamed(body, creature=c) for body in header["bodies"]]
        new["suckers"] += [renamed(s, body=first + s["body"]) for s in header["suckers"]]
        new["goals"] += [renamed(goal, creature=c) for goal in header["goals"]]
    header.update(new)
    header.pop("replay", None)  # nobody replays here
    apart = np.repeat(np.arange(creatures) * 1.5, per)[None, :, None] * [1.0, 0.0, 0.0]
    arrays = {
        "pos": (np.tile(single.pos, (1, creatures, 1)) + apart).astype(np.float32),
        "quat": np.tile(single.quat, (1, creatures, 1)),
        "sucker_attached": np.tile(single.sucker_attached, (1, creatures)),
        "sucker_anchor": np.tile(single.sucker_anchor, (1, creatures, 1)),
        "goal_pos": np.tile(single.tracks["goal_pos"], (creatures, 1)),
        "goal_active": np.tile(single.tracks["goal_active"], (1, creatures)),
    }
    Take.from_arrays(header, arrays).save(path)


def test_export_refuses_a_glb_too_large_before_reading_a_frame(tmp_path: Path) -> None:
    """A take of 1,024 creatures whose frames are damaged: the refusal comes first, so
    export read only the header; with the frames whole, a USD or a lighter glb is fine."""
    take = tmp_path / "crowd.npz"
    _crowd_take(1024, take)
    damaged = tmp_path / "damaged.npz"
    with zipfile.ZipFile(take) as source, zipfile.ZipFile(damaged, "w") as out:
        for entry in source.infolist():
            data = source.read(entry)
            if entry.filename == "pos.000000.npy":  # the poses cut short: loading them fails
                data = data[: len(data) // 2]
            out.writestr(entry, data)
    heavy = ("--rings-per-link", "14", "--sides", "64")  # 62,332 vertices, 4.3 MB a creature
    done = _run("export", str(damaged), "--out", "crowd.glb", *heavy, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and done.stdout == ""
    assert done.stderr.startswith("error: crowd.glb: the glb would be up to")
    assert "(1,024 creatures x 2 frames, skinned)" in done.stderr
    assert done.stderr.rstrip().endswith(
        ": export to .usdc, or fewer creatures or a lighter mesh (--rings-per-link, --sides:"
        " not one frame fits)"
    )
    assert not (tmp_path / "crowd.glb").exists()
    with pytest.raises(GlbTooLarge, match="the glb would be up to"):  # the API refuses too
        write_skinned_glb(Take.load(take), tmp_path / "crowd.glb", Skin(Detail(14, 64)))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.npz", "damaged.npz"]
    broken = _run("export", str(damaged), "--out", "light.glb", cwd=tmp_path)
    assert (
        broken.returncode == 2
        and "pos chunk 0: shape (2, 62464, 3) holds more than" in broken.stderr
    )


def test_a_mesh_past_16_bit_indices_is_refused_before_baking(tmp_path: Path) -> None:
    plan = BakePlan.make({"version": 1, "creatures": [_creature("octo", 0.0)]}, seconds=1.0)
    problem = plan.glb_problem("octo.glb", Skin(Detail(64, 128)), None)
    assert problem is not None and problem.startswith("creature octo: ")
    assert problem.endswith(" skinned vertices, over glTF's 16-bit indices here; use fewer"
                            " rings per link or sides")  # fmt: skip
    assert plan.glb_problem("octo.glb", Skin(Detail(16, 32)), None) is None
    shapes = shapes_of_scene(plan.scene, plan.frames)
    assert glb_problem("octo.glb", glb_size(shapes, Detail(64, 128)), ()) == problem


def test_a_glb_past_what_blender_imports_is_written_with_a_note() -> None:
    """5 s of the 1,024 crowd, skinned: 0.8 GB, in glTF's bounds but about 17 GB for
    Blender's importer, more than a 16 GB machine has and less than 24 GB."""
    gb = 10**9
    note = _uniform_plan(301).glb_note("crowd.glb", Skin(), None, memory=16 * gb)
    assert note == (
        "crowd.glb: up to 0.8 GB; Blender's glTF importer would need about 17.5 GB of"
        " memory to open it, more than the 16.0 GB here: for Blender, write .usdc, or fewer"
        " frames or creatures"
    )
    assert _uniform_plan(301).glb_note("crowd.glb", Skin(), None, memory=24 * gb) is None
    assert _uniform_plan(301).glb_problem("crowd.glb", Skin(), None) is None
