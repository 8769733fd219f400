"""A module or file beside a scene imports without PYTHONPATH, from any working folder.

The scene's folder goes first on `sys.path` while plugins are imported; a relative
plugin file may not leave that folder; a plugin that fails to import is one line
naming it (exit 2). Driven through the CLI (`ecs-tentacles run/bake/play`), once as
a real process with no PYTHONPATH.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.take import Take

# A system that says when it runs (on stderr: `--json` keeps stdout for the summary)
WAVE = '''
import sys

from ecs_tentacles.system import System


class Wave(System):
    """Reads the frame; writes nothing (says on stderr that it ran)."""

    name = "wave"
    stage = "act"

    def process(self, world, dt):
        print(f"wave ran at frame {world.frame}", file=sys.stderr)
'''
RAN = "wave ran at frame 0\nwave ran at frame 1\n"
CREATURE = {
    "name": "octo",
    "position": [0, 0],
    "tentacles": {"count": 3, "links": 2},
    "goals": [{"position": [1, 0]}],
}


def _scene(folder: Path, name: str, **fields: object) -> Path:
    path = folder / name
    path.write_text(json.dumps({"version": 1, "creatures": [CREATURE], **fields}))
    return path


@pytest.fixture
def elsewhere(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A scene folder holding `mywave.py`; the working folder is another one."""
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    (scenes / "mywave.py").write_text(WAVE)
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    monkeypatch.delenv("PYTHONPATH", raising=False)
    monkeypatch.delitem(sys.modules, "mywave", raising=False)
    before = list(sys.path)
    yield scenes
    assert sys.path == before  # the scene's folder was only on the path while importing
    assert list(cwd.iterdir()) == []


def test_systems_list_module_beside_the_scene_runs_from_another_folder(
    elsewhere: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = _scene(elsewhere, "scene.json", systems=["mywave:Wave"])
    assert main(["run", str(scene), "--frames", "2", "--allow-systems", "--quiet", "--json"]) == 0
    captured = capsys.readouterr()
    assert (json.loads(captured.out)["frames"], captured.err) == (2, RAN)


def test_plugin_from_a_file_beside_the_scene_runs_and_bakes(
    elsewhere: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = _scene(elsewhere, "scene.json", plugins={"x": {"from": "mywave.py"}})
    assert main(["run", str(scene), "--frames", "2", "--allow-systems", "--quiet"]) == 0
    assert capsys.readouterr().err == RAN
    out = elsewhere / "take.npz"
    args = ["bake", str(scene), "--seconds", "0.02", "--out", str(out), "--quiet"]
    assert main([*args, "--allow-systems"]) == 0
    assert Take.load(out).frames == 2
    assert capsys.readouterr().err.endswith(
        ".npz: 2 frames at 60 fps (simulated at 60 fps), seed 0\nwave ran at frame 0\n"
    )
    out.unlink()
    assert main(args) == 2  # not allowed: nothing imported, nothing written
    assert capsys.readouterr().err == (
        f"error: {scene}: plugins.x: runs code from 'mywave.py'; allow it with --allow-systems"
        " (API: allow_systems=True)\n"
    )
    assert not out.exists()


def test_a_real_process_finds_the_module_without_pythonpath(elsewhere: Path) -> None:
    scene = _scene(elsewhere, "scene.json", systems=["mywave:Wave"])
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(
        [sys.executable, "-m", "ecs_tentacles", "run", str(scene), "--frames", "2"]
        + ["--allow-systems", "--quiet", "--json"],
        capture_output=True,
        text=True,
        env=env,
        cwd=Path.cwd(),
        check=False,
    )
    assert (done.returncode, done.stderr) == (0, RAN)
    assert json.loads(done.stdout)["frames"] == 2


def test_a_file_outside_the_scene_folder_is_refused(
    elsewhere: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (elsewhere.parent / "evil.py").write_text("raise SystemExit('must never run')\n")
    scene = _scene(elsewhere, "scene.json", plugins={"x": {"from": "../evil.py"}})
    assert main(["run", str(scene), "--frames", "1", "--allow-systems", "--quiet"]) == 2
    assert capsys.readouterr().err == (
        f"error: {scene}: plugins.x: '../evil.py' leaves the scene's folder {elsewhere}\n"
    )


@pytest.mark.parametrize(
    ("source", "problem"),
    [
        ("raise RuntimeError('no config file')\n", "RuntimeError: no config file"),
        ("x = (\n", "SyntaxError: '(' was never closed (broken.py, line 1)"),
        (
            "import no_such_module_xyz\n",
            "ModuleNotFoundError: No module named 'no_such_module_xyz'",
        ),
    ],
)
def test_a_plugin_file_that_fails_to_import_is_one_line(
    elsewhere: Path, capsys: pytest.CaptureFixture[str], source: str, problem: str
) -> None:
    (elsewhere / "broken.py").write_text(source)
    scene = _scene(elsewhere, "scene.json", plugins={"x": {"from": "broken.py"}})
    assert main(["run", str(scene), "--frames", "1", "--allow-systems", "--quiet"]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"error: {scene}: plugins.x: cannot import 'broken.py': {problem}\n"
    assert captured.out == ""


def test_a_systems_module_that_raises_at_import_is_one_line(
    elsewhere: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (elsewhere / "broken_mod.py").write_text("raise RuntimeError('no config file')\n")
    scene = _scene(elsewhere, "scene.json", systems=["broken_mod:Wave"])
    assert main(["run", str(scene), "--frames", "1", "--allow-systems", "--quiet"]) == 2
    assert capsys.readouterr().err == (
        "error: systems[0]: cannot import 'broken_mod:Wave': RuntimeError: no config file\n"
    )
    assert "broken_mod" not in sys.modules


@pytest.mark.parametrize(
    ("source", "problem"),
    [
        (
            "class P(Plugin):\n    def __init__(self, config=None):\n"
            "        raise ValueError('gain')\n",
            "plugins.x: cannot make 'made.py': ValueError: gain",
        ),
        (
            "class P(Plugin):\n    def systems(self):\n        return [undefined]\n",
            "plugins.x: systems() raised NameError: name 'undefined' is not defined",
        ),
    ],
    ids=["constructor", "systems"],
)
def test_a_plugin_that_cannot_be_made_is_one_line(
    elsewhere: Path, capsys: pytest.CaptureFixture[str], source: str, problem: str
) -> None:
    (elsewhere / "made.py").write_text("from ecs_tentacles.plugin import Plugin\n\n" + source)
    scene = _scene(elsewhere, "scene.json", plugins={"x": {"from": "made.py"}})
    assert main(["run", str(scene), "--frames", "1", "--allow-systems", "--quiet"]) == 2
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith("error: ") and line.endswith(problem)
