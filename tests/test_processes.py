"""No command runs a module that lies beside a scene or in the working folder.

An attacker's scene folder and the folder a user runs from each hold a shadow module
for every name the project and its dependencies could import (the standard library's
names and every installed distribution's top-level names): each shadow, if imported,
writes its name and folder to a record. Every command is run as a user runs it (the
`ecs-tentacles` script, a real process, the working folder full of shadows) on a
scene that reaches the lazy imports: a heightfield image, an uncached mesh obstacle
(the mesh worker starts), fur, a bundled plugin, a herding level, a local Ray bake
(the reaper and Ray's workers start), exports and the sandbox's save. No shadow runs.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

SCENES = Path(__file__).resolve().parents[1] / "assets" / "scenes"
ROCK = "v 0 0 0\nv 0.4 0 0\nv 0 0.4 0\nv 0 0 0.4\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
SCENE = {
    "version": 1,
    "name": "shadowed",
    "seed": 3,
    "plugins": {"wander": {"radius": 1.0, "interval": 0.5}},
    "terrain": {
        "heightfield": {"size": [8, 8], "image": "hill.png", "height": 0.3},
        "obstacles": [{"shape": "mesh", "file": "rock.obj", "position": [3, 3, 0]}],
    },
    "creatures": [
        {
            "name": "hedgehog",
            "position": [-1, -1],
            "tentacles": {"count": 6, "links": 5},
            "fur": {"preset": "hedgehog", "groom": {"count": 60, "seed": 7}},
        },
        {"name": "plain", "position": [1, 1], "tentacles": {"count": 6, "links": 5}},
    ],
}
SAVE = """
import sys
from ecs_tentacles.render import configure
configure(headless=True)
from pyglet.window import key
from pyglet.event import EventDispatcher
from ecs_tentacles.render.sandbox import Sandbox
from ecs_tentacles.terrain.panel import TerrainPanel
sandbox = Sandbox(sys.argv[1], headless=True, width=320, height=180)
sandbox.render()
EventDispatcher.dispatch_event(sandbox.window, "on_key_press", key.S, key.MOD_CTRL)
EventDispatcher.dispatch_event(sandbox.window, "on_key_release", key.S, key.MOD_CTRL)
panel = TerrainPanel(sandbox)
panel.save()
assert panel.message.startswith("saved "), panel.message
sandbox.close()
print("saved")
"""


def shadow_names() -> list[str]:
    """Every module name an import could look for first on the path: the standard
    library's and each installed distribution's top-level packages."""
    names = set(sys.stdlib_module_names) | set(importlib.metadata.packages_distributions())
    return sorted(n for n in names if n.isidentifier())


def plant_shadows(folder: Path, record: Path, label: str) -> int:
    """A `NAME.py` in `folder` for every shadow name, each appending `label:NAME` to
    `record` when run (with builtins only: nothing it imports could be shadowed)."""
    names = shadow_names()
    for name in names:
        line = f"{label}:{name}\n"
        (folder / f"{name}.py").write_text(f"open({str(record)!r}, 'a').write({line!r})\n")
    return len(names)


@pytest.fixture(scope="module")
def folders(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A scene folder and a working folder full of shadows; caches and user data in a
    fresh home, so the mesh is decomposed (the worker starts) and nothing is reused."""
    from PIL import Image

    root = tmp_path_factory.mktemp("shadows")
    scene, work, home = root / "scene", root / "work", root / "home"
    for folder in (scene, work, home):
        folder.mkdir()
    record = root / "ran.txt"
    record.touch()
    assert plant_shadows(scene, record, "scene") > 300
    plant_shadows(work, record, "work")
    Image.fromarray(np.tile(np.arange(16, dtype=np.uint8) * 8, (16, 1))).save(scene / "hill.png")
    (scene / "rock.obj").write_text(ROCK)
    (scene / "shadowed.json").write_text(json.dumps(SCENE))
    shutil.copy(SCENES / "herding_1_field.json", scene / "herding.json")
    return {"scene": scene, "work": work, "home": home, "record": record}


def command_line() -> list[str]:
    """The `ecs-tentacles` script beside this interpreter, as a user runs it."""
    script = Path(sys.executable).with_name("ecs-tentacles")
    return [str(script)] if script.is_file() else [sys.executable, "-P", "-m", "ecs_tentacles"]


def run_in(folders: dict[str, Path], argv: list[str], timeout: float = 240) -> str:
    """Run `argv` in the working folder; fail with its output unless it exits 0."""
    home = folders["home"]
    env = dict(os.environ)
    env.update(
        HOME=str(home),
        XDG_CACHE_HOME=str(home / "cache"),
        XDG_DATA_HOME=str(home / "data"),
        XDG_CONFIG_HOME=str(home / "config"),
        XDG_STATE_HOME=str(home / "state"),
    )
    env.pop("PYTHONPATH", None)
    done = subprocess.run(
        argv, cwd=folders["work"], env=env, capture_output=True, text=True, timeout=timeout
    )
    assert_no_shadow_ran(folders)  # first: a shadow that ran may also have broken the command
    assert done.returncode == 0, f"{argv}: exit {done.returncode}\n{done.stdout}\n{done.stderr}"
    return done.stdout + done.stderr


def assert_no_shadow_ran(folders: dict[str, Path]) -> None:
    ran = sorted(set(folders["record"].read_text().split()))
    assert not ran, f"shadow modules ran: {', '.join(ran)}"


COMMANDS = {
    "validate": ["validate", "{scene}/shadowed.json", "{scene}/herding.json"],
    "run": ["run", "{scene}/shadowed.json", "--frames", "3"],
    "bake": ["bake", "{scene}/shadowed.json", "--seconds", "0.05", "--out", "plain.npz", "--quiet"],
    "play": ["play", "{scene}/herding.json", "--headless", "--frames", "3", "--width", "160",
             "--height", "96", "--screenshot", "shot.png", "--video", "clip.mp4", "--quiet"],
    "systems": ["systems", "{scene}/shadowed.json"],
    "schema": ["schema", "{scene}/shadowed.json", "--out", "schema.json"],
    "migrate": ["migrate", "{scene}/shadowed.json", "--out", "migrated.json"],
    "create": ["create", "--from", "{scene}/shadowed.json", "--out", "created.json"],
    "crowd": ["crowd", "4", "--terrain", "rocky", "--out", "crowd.json"],
    "bench": ["bench", "--crowd", "4", "--frames", "3", "--warmup", "1", "--quiet"],
}  # fmt: skip


def test_python_m_takes_the_working_folder_off_the_path(folders: dict[str, Path]) -> None:
    """`python -m ecs_tentacles` finds the package itself on the path Python made, with
    the working folder first (README: use `ecs-tentacles` or `python -P -m`); from then
    on, nothing more comes from there."""
    itself = folders["work"] / "ecs_tentacles.py"
    itself.rename(itself.with_suffix(".aside"))
    try:
        scene = str(folders["scene"] / "shadowed.json")
        out = run_in(folders, [sys.executable, "-m", "ecs_tentacles", "validate", scene])
    finally:
        itself.with_suffix(".aside").rename(itself)
    assert "ok (2 creatures" in out


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_command_runs_no_module_from_the_scene_or_working_folder(
    folders: dict[str, Path], name: str
) -> None:
    argv = [a.format(scene=folders["scene"]) for a in COMMANDS[name]]
    run_in(folders, [*command_line(), *argv])


def test_a_bake_on_a_local_ray_and_its_exports_run_no_shadow(folders: dict[str, Path]) -> None:
    pytest.importorskip("ray", reason="the `ray` extra is not installed")
    pytest.importorskip("pxr", reason="usd-core is not installed")
    scene = str(folders["scene"] / "shadowed.json")
    out = run_in(folders, [*command_line(), "bake", scene, "--seconds", "0.05", "--out",
                           "ray.npz", "--ray", "--cpus", "2", "--quiet"])  # fmt: skip
    assert "shard" in out
    for target in ("ray.usda", "ray.glb"):
        run_in(folders, [*command_line(), "export", "ray.npz", "--out", target, "--quiet"])
        assert (folders["work"] / target).stat().st_size > 0


def test_the_sandbox_saves_without_running_a_shadow(folders: dict[str, Path]) -> None:
    scene = str(folders["scene"] / "shadowed.json")
    out = run_in(folders, [sys.executable, "-P", "-c", SAVE, scene])
    assert "saved" in out
    saved = sorted(p.name for p in folders["work"].glob("shadowed_*.json"))
    assert saved, "Ctrl+S and the terrain section's save wrote nothing"
