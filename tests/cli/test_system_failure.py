"""A user system that raises: headless runs exit 1 with one line and the user's traceback.

The first line names the system, its plugin and the frame; then comes the traceback
of the user's code only (starting in their `process` or `substep`), and nothing is
written.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ecs_tentacles.cli import main

FAILING = '''
from ecs_tentacles.system import System


def half(x):
    return x / 0


class Wave(System):
    """Reads the frame; fails at frame 3."""

    name = "wave"
    stage = "act"

    def process(self, world, dt):
        if world.frame == 3:
            half(world.frame)


class Ready(System):
    """Fails to set up."""

    name = "ready"

    def setup(self, world):
        world.waves


class Quit(System):
    """Calls sys.exit(0) at frame 3."""

    name = "quit"
    stage = "act"

    def process(self, world, dt):
        if world.frame == 3:
            import sys

            sys.exit(0)


class Poison(System):
    """Writes NaN into the first body's position at frame 2, after the physics."""

    name = "poison"
    stage = "output"

    def process(self, world, dt):
        if world.frame == 2:
            world.transforms.pos[0, 0] = float("nan")


class Shake(System):
    """A substep hook that fails at frame 2."""

    name = "shake"
    stage = "physics"
    before = ("physics",)

    def substep(self, world, index, dt):
        if world.frame == 2 and index == 5:
            raise KeyError("tentacle 9")
'''


def _line(code: str) -> int:
    """The line number of `code` in FAILING."""
    return next(i for i, line in enumerate(FAILING.splitlines(), 1) if code in line)


FIRST = (
    "error: system 'wave' (plugin 'mine') failed at frame 3: ZeroDivisionError: division by zero"
)


@pytest.fixture
def failing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "failing.py").write_text(FAILING)
    scene = {
        "version": 1,
        "plugins": {"mine": {"from": "failing.py:Wave"}},
        "creatures": [{"name": "octo", "tentacles": {"count": 3, "links": 2}}],
    }
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    monkeypatch.chdir(tmp_path)
    return path


def _use_plugin(scene_path: Path, key: str, source: str) -> None:
    """The scene at `scene_path` turns on plugin `key` from `source` instead."""
    scene = json.loads(scene_path.read_text())
    scene["plugins"] = {key: {"from": source}}
    scene_path.write_text(json.dumps(scene))


def _user_traceback(err: str) -> list[str]:
    """The traceback's File lines and the last line, without Python's ~~^~~ markers."""
    return [
        line.strip()
        for line in err.splitlines()[1:]
        if line.lstrip().startswith(("File", "Traceback")) or not line.startswith(" ")
    ]


def test_run_exits_1_naming_the_system_then_the_user_traceback(
    failing: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", str(failing), "--frames", "10", "--allow-systems", "--quiet"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.splitlines()[0] == FIRST
    source = failing.parent / "failing.py"
    assert _user_traceback(captured.err) == [
        "Traceback (most recent call last):",
        f'File "{source}", line {_line("half(world.frame)")}, in process',
        f'File "{source}", line {_line("return x / 0")}, in half',
        "ZeroDivisionError: division by zero",
    ]
    assert "world.py" not in captured.err  # the engine's frames are not the user's concern


def test_bake_exits_1_and_writes_nothing(failing: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = failing.parent / "take.npz"
    args = ["bake", str(failing), "--seconds", "1", "--out", str(out), "--allow-systems"]
    assert main([*args, "--quiet"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("bake: ") and err[1] == FIRST
    assert err[-1] == "ZeroDivisionError: division by zero"
    assert sorted(p.name for p in failing.parent.iterdir()) == ["failing.py", "scene.json"]


def test_a_failing_substep_hook_is_named_not_physics(
    failing: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _use_plugin(failing, "shaker", "failing.py:Shake")
    assert main(["run", str(failing), "--frames", "10", "--allow-systems", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.splitlines()[0] == (
        "error: system 'shake' (plugin 'shaker') failed at frame 2: KeyError: 'tentacle 9'"
    )
    assert _user_traceback(err) == [
        "Traceback (most recent call last):",
        f'File "{failing.parent / "failing.py"}", line {_line("raise KeyError")}, in substep',
        "KeyError: 'tentacle 9'",
    ]


def test_debug_shows_the_whole_chain(failing: Path) -> None:
    from ecs_tentacles.system import SystemFailure

    with pytest.raises(SystemFailure) as caught:
        main(["--debug", "run", str(failing), "--frames", "10", "--allow-systems", "--quiet"])
    assert isinstance(caught.value.__cause__, ZeroDivisionError)
    assert (caught.value.label, caught.value.frame) == ("wave", 3)


def test_a_failing_setup_is_named_with_its_traceback(
    failing: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _use_plugin(failing, "mine", "failing.py:Ready")
    assert main(["run", str(failing), "--frames", "10", "--allow-systems", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.splitlines()[0].startswith(
        "error: system 'ready' (plugin 'mine') failed at frame 0: AttributeError: 'World'"
        " object has no attribute 'waves'"
    )
    assert (
        _user_traceback(err)[1]
        == f'File "{failing.parent / "failing.py"}", line {_line("world.waves")}, in setup'
    )


def test_a_system_that_calls_sys_exit_fails_the_bake_with_one_line(
    failing: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _use_plugin(failing, "quitter", "failing.py:Quit")
    out = failing.parent / "take.npz"
    args = ["bake", str(failing), "--seconds", "1", "--out", str(out), "--allow-systems"]
    assert main([*args, "--quiet"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[1] == "error: system 'quit' (plugin 'quitter') failed at frame 3: SystemExit: 0"
    assert err[-1] == "SystemExit: 0"
    assert not out.exists()


def test_a_plugin_that_exits_while_importing_is_a_scene_error(
    failing: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (failing.parent / "exits.py").write_text("import sys\nsys.exit(3)\n")
    _use_plugin(failing, "exits", "exits.py")
    assert main(["run", str(failing), "--frames", "2", "--allow-systems", "--quiet"]) == 2
    assert capsys.readouterr().err == (
        f"error: {failing}: plugins.exits: cannot import 'exits.py': SystemExit: 3\n"
    )


@pytest.mark.parametrize("suffix", [".npz", ".glb"])
def test_a_bake_whose_plugin_wrote_nan_writes_nothing(
    failing: Path, suffix: str, capsys: pytest.CaptureFixture[str]
) -> None:
    _use_plugin(failing, "poison", "failing.py:Poison")
    out = failing.parent / f"take{suffix}"
    args = ["bake", str(failing), "--seconds", "0.2", "--out", str(out), "--allow-systems"]
    assert main([*args, "--quiet"]) == 1
    err = capsys.readouterr().err.splitlines()
    verb = "write" if suffix == ".npz" else "export"
    assert err[1:] == [
        f"error: {out}: cannot {verb} this take: pos: non-finite value nan at (3, 0, 0)"
    ]
    assert not out.exists()
