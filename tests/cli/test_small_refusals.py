"""Small refusals, each one line naming the field or the file, in real processes."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.world import World


def cli(*args: str, cwd: Path | None = None, prefix: tuple[str, ...] = ()) -> tuple[int, str, str]:
    """Run `python -m ecs_tentacles ARGS`; (exit code, stdout, stderr)."""
    done = subprocess.run(
        [*prefix, sys.executable, "-m", "ecs_tentacles", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
    )
    return done.returncode, done.stdout, done.stderr


@pytest.fixture(scope="module")
def take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("take") / "good.npz"
    code, _, err = cli("bake", "octopus", "--seconds", "0.05", "--out", str(path), "--quiet")
    assert code == 0, err
    return path


def _edited(good: Path, bad: Path, change: Callable[[dict[str, Any]], object]) -> Path:
    with np.load(good) as npz:
        arrays = {name: npz[name] for name in npz.files}
    header = json.loads(arrays["header"].tobytes())
    change(header)
    arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    np.savez(bad, **arrays)
    return bad


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda h: h["creatures"][0].update(tentacles=[]), "header.creatures[0].tentacles: "),
        (lambda h: h["creatures"][0]["tentacles"].__setitem__(3, []), "tentacles[3]: "),
    ],
    ids=["no_tentacle", "a_tentacle_without_links"],
)
def test_a_take_with_a_creature_without_tentacles_is_refused_when_read(
    take: Path, tmp_path: Path, change: Callable[[dict[str, Any]], object], field: str
) -> None:
    bad = _edited(take, tmp_path / "bad.npz", change)
    for out in ("x.glb", "x.usda"):
        code, _, err = cli("export", str(bad), "--out", str(tmp_path / out), "--quiet")
        assert code == 2, err
        (line,) = err.splitlines()
        assert line.startswith(f"error: {bad}: ") and field in line, line
        assert not (tmp_path / out).exists()


def test_a_full_disk_is_one_line_naming_the_file(take: Path, tmp_path: Path) -> None:
    """A 64 kB tmpfs (mounted in a user and mount namespace of the command's own)."""
    full = tmp_path / "full"
    full.mkdir()
    unshare = shutil.which("unshare")
    mount = f"mount -t tmpfs -o size=64k none {full} &&"
    probe = subprocess.run(
        [unshare or "unshare", "-rm", "sh", "-c", f"{mount} true"], capture_output=True
    )
    if unshare is None or probe.returncode != 0:
        pytest.skip("no unshare -rm here to mount a small tmpfs")
    for args in (
        ("export", str(take), "--out", str(full / "x.usda"), "--quiet"),
        ("export", str(take), "--out", str(full / "x.glb"), "--quiet"),
        ("bake", "octopus", "--seconds", "0.5", "--out", str(full / "t.npz"), "--quiet"),
    ):
        target = args[args.index("--out") + 1]
        done = subprocess.run(
            ["unshare", "-rm", "sh", "-c", f'{mount} exec "$@"', "sh"]
            + [sys.executable, "-m", "ecs_tentacles", *args],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 1, done.stderr[-500:]
        (line,) = [x for x in done.stderr.splitlines() if x.startswith("error")]
        assert line == f"error: {target}: cannot write: no space left on device; nothing written"
        assert len(done.stderr) < 1000  # not USD's error for every buffer it flushed


def test_a_nan_radius_is_one_problem_not_also_a_missing_radius() -> None:
    rock = {"shape": "sphere", "position": [3, 0, 0], "radius": float("nan")}
    scene = {"version": 1, "terrain": {"obstacles": [rock]}, "creatures": [{"name": "a"}]}
    with pytest.raises(SceneError) as error:
        World.from_scene(scene)  # a script's dict can hold a NaN
    assert error.value.problems == ["terrain.obstacles[0].radius: must be a finite number, got NaN"]
    # a problem that is there besides is still reported
    del rock["radius"]
    rock.update(shape="cylinder", radius=float("nan"))
    with pytest.raises(SceneError) as error:
        load_scene(scene)
    assert error.value.problems == [
        "terrain.obstacles[0].radius: must be a finite number, got NaN",
        "terrain.obstacles[0]: a cylinder needs 'height'",
    ]


def test_numpy_heights_are_named_as_such_in_one_line() -> None:
    field = {"size": [4, 4], "heights": np.zeros((3, 3))}
    scene = {"version": 1, "terrain": {"heightfield": field}, "creatures": [{"name": "a"}]}
    with pytest.raises(SceneError) as error:
        load_scene(scene)
    assert error.value.problems == [
        "terrain.heightfield.heights: must be an array, got a numpy array of shape (3, 3)"
        " (give a list: .tolist())"
    ]


def test_a_negative_focus_x_is_taken_as_written(tmp_path: Path) -> None:
    code, out, err = cli("run", "octopus", "--frames", "2", "--focus", "-2,1,3", "--json")
    assert code == 0, err
    assert json.loads(out)["frames"] == 2
    code, _, err = cli("run", "octopus", "--frames", "2", "--focus", "-x,1,3")
    assert code == 2
    (line,) = err.splitlines()
    assert "a value that starts with '-' is written --focus=VALUE" in line, line


def test_a_hundred_thousand_character_name_is_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "long.json"
    path.write_text(json.dumps({"version": 1, "creatures": [{"name": "a" * 100_000}]}))
    code, _, err = cli("validate", str(path))
    assert code == 2
    assert err == f"error: {path}: creatures[0].name: must have at most 64 characters, got 100000\n"


def test_a_longest_name_spawned_again_gets_a_suffix_within_the_cap() -> None:
    name = "b" * 64
    with World.from_scene({"version": 1, "creatures": [{"name": name}]}) as world:
        again = world.spawn({"name": name}, position=(20, 0))
        from ecs_tentacles.components import Creature

        assert world.component(again, Creature).name == "b" * 62 + "_2"
