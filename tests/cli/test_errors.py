"""The CLI speaks one way: every bad invocation of every command is one stderr line.

`error: <where>: <what>`, exit 2 for bad input and 1 for a failure at run time, no
traceback, no usage block. In-process for speed; a few cases also as real processes
(`python -m ecs_tentacles`, no display).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ecs_tentacles.cli import main


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("cli")
    take = folder / "take.npz"
    assert main(["bake", "three_goals", "--seconds", "0.05", "--out", str(take), "--quiet"]) == 0
    junk = folder / "junk.npz"
    junk.write_bytes(b"PK\x03\x04 not really")
    fifo = folder / "fifo.json"
    os.mkfifo(fifo)
    deep = folder / "deep.json"
    deep.write_text('{"version": 1, "x": ' + "[" * 500 + "]" * 500 + "}")
    floats = folder / "floats.json"
    floats.write_text(json.dumps({"version": 1, "creatures": [{"tentacles": {"count": 8.0}}]}))
    return {"take": take, "junk": junk, "fifo": fifo, "deep": deep, "floats": floats}


def _cases(f: dict[str, Path], out: Path) -> list[tuple[list[str], int]]:
    take, fifo = str(f["take"]), str(f["fifo"])
    npz, glb, js = str(out / "t.npz"), str(out / "t.glb"), str(out / "c.json")
    return [
        ([], 2),
        (["frob"], 2),
        (["--max-scene-mb", "0", "validate", "octopus"], 2),
        (["validate"], 2),
        (["validate", "octopuss"], 2),
        (["validate", fifo], 2),
        (["validate", "/dev/zero"], 2),
        (["validate", str(f["deep"])], 2),
        (["validate", str(f["floats"])], 2),
        (["run"], 2),
        (["run", "octopus", "--frames", "0"], 2),
        (["run", "octopus", "--frames", "ten"], 2),
        (["run", "octopus", "--seed", "-1"], 2),
        (["run", "octopuss"], 2),
        (["run", "/dev/zero"], 2),
        (["run", "octopus", "--bogus"], 2),
        (["run", "octopus", "--lod", "yes"], 2),
        (["run", "octopus", "--focus", "1,2,3,4"], 2),
        (["play", "octopus", "--headless", "--focus", "1,nan,3"], 2),
        (["play", "octopus", "--headless", "--lod", "1"], 2),
        (["bake", "octopus", "--seconds", "1", "--out", npz, "--focus=0,0,-1"], 2),
        (["bake", "octopus", "--seconds", "1", "--out", npz, "--lod"], 2),
        (["play", "octopus", "--width", "0"], 2),
        (["play", "octopus", "--height", "721"], 2),
        (["play", "octopus", "--screenshot", str(out / "s.png")], 2),
        (["play", "octopus", "--headless", "--video", "c.avi"], 2),
        (["play", "octopus"], 2),  # no display
        (["play", "octopuss", "--headless"], 2),
        (["play", fifo, "--headless"], 2),
        (["bake", "octopus"], 2),
        (["bake", "octopus", "--seconds", "0", "--out", npz], 2),
        (["bake", "octopus", "--seconds", "1e400", "--out", npz], 2),
        (["bake", "octopus", "--seconds", "1", "--out", "x.fbx"], 2),
        (["bake", "octopus", "--seconds", "1", "--out", "no/such/t.npz"], 2),
        (["bake", "octopus", "--seconds", "1", "--out", npz, "--fps", "0"], 2),
        (["bake", "octopus", "--seconds", "0.001", "--out", npz], 2),
        (["bake", str(f["floats"]), "--seconds", "1", "--out", npz], 2),
        (["export"], 2),
        (["export", str(out / "none.npz"), "--out", glb], 2),
        (["export", str(f["junk"]), "--out", glb], 2),
        (["export", take, "--out", "x.fbx"], 2),
        (["export", take, "--out", npz], 2),
        (["export", take, "--out", "/proc/t.glb"], 1),  # cannot write there: run time
        (["create", "--tentacles", "0", "--out", js], 2),
        (["create", "--tentacles", "17", "--out", js], 2),
        (["create", "--links", "8.5", "--out", js], 2),
        (["create", "--tentacle", "two:links=3", "--out", js], 2),
        (["create", "--out", "x.txt"], 2),
        (["create", "--from", "octopuss", "--out", js], 2),
        (["create"], 2),  # no display
    ]


def test_every_command_with_bad_arguments_gives_one_line(
    files: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    commands = set()
    for argv, expected in _cases(files, tmp_path):
        try:
            code = main(argv)
        except SystemExit as stop:
            code = int(stop.code or 0)
        captured = capsys.readouterr()
        lines = captured.err.splitlines()
        assert code == expected, (argv, captured.err)
        assert len(lines) == 1 and lines[0].startswith("error: "), (argv, captured.err)
        assert "Traceback" not in captured.err and captured.out == ""
        commands.add(next((a for a in argv if not a.startswith("-")), ""))
    assert {"validate", "run", "play", "bake", "export", "create"} <= commands
    assert list(tmp_path.iterdir()) == []


NO_DISPLAY = {
    ("play", "octopus"): "error: play: no display to open a window on; use --headless",
    ("create",): "error: create: no display to open the creator window on; use --out FILE",
}


@pytest.mark.parametrize("argv", sorted(NO_DISPLAY))
def test_without_a_display_play_and_create_say_so_in_one_line(argv: tuple[str, ...]) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    process = subprocess.run(
        [sys.executable, "-m", "ecs_tentacles", *argv],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert process.returncode == 2
    assert process.stderr.startswith(NO_DISPLAY[argv]) and process.stderr.count("\n") == 1


def test_python_dash_m_and_did_you_mean() -> None:
    process = subprocess.run(
        [sys.executable, "-m", "ecs_tentacles", "validate", "octopuss"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert process.returncode == 2
    assert process.stderr == (
        "error: octopuss: no such file or bundled scene; did you mean 'octopus'?\n"
    )


def test_unexpected_failures_are_one_line_unless_debug(
    files: dict[str, Path], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the disk\nis on fire")

    monkeypatch.setattr("ecs_tentacles.cli.export.save", broken)
    argv = ["export", str(files["take"]), "--out", "/tmp/never.glb"]
    assert main(argv) == 1
    assert capsys.readouterr().err == (
        "error: export: RuntimeError: the disk is on fire (--debug shows where)\n"
    )
    with pytest.raises(RuntimeError):
        main(["--debug", *argv])


TOO_BIG = {
    ("bake", "octopus", "--seconds", "1e9"): (
        "error: argument --seconds: 1e+09 s at 60 fps is 60,000,000,001 frames; a take holds"
        " at most 1000000 (bake fewer seconds or at a lower --fps)"
    ),
    ("bake", "octopus", "--seconds", "1e300"): (
        "error: argument --seconds: 1e+300 s at 60 fps is 6e+301 frames; a take holds at most"
        " 1000000 (bake fewer seconds or at a lower --fps)"
    ),
    ("bake", "octopus", "--seconds", "1", "--rings-per-link", "100000000"): (
        "error: argument --rings-per-link: must be <= 64, got 100000000"
        " (see ecs-tentacles bake --help)"
    ),
    ("bake", "octopus", "--seconds", "1", "--sides", "4096"): (
        "error: argument --sides: must be <= 256, got 4096 (see ecs-tentacles bake --help)"
    ),
    ("bake", "octopus", "--seconds", "1", "--seed", "1" + "0" * 30): (
        "error: argument --seed: must be <= 9223372036854775807, got 1"
        + "0" * 30
        + " (see ecs-tentacles bake --help)"
    ),
    ("run", "octopus", "--frames", "100000000000"): (
        "error: argument --frames: must be <= 10000000, got 100000000000"
        " (see ecs-tentacles run --help)"
    ),
    ("bench", "--crowd", "4", "--frames", "10000000000"): (
        "error: argument --frames: must be <= 1000000, got 10000000000"
        " (see ecs-tentacles bench --help)"
    ),
    ("bench", "octopus", "--threads", "100000"): (
        "error: argument --threads: must be <= 256, got 100000 (see ecs-tentacles bench --help)"
    ),
}


@pytest.mark.parametrize("argv", sorted(TOO_BIG))
def test_numbers_too_big_to_run_are_refused_up_front(
    argv: tuple[str, ...], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = list(argv)
    if args[0] == "bake":
        args += ["--out", str(tmp_path / "take.npz")]
    try:
        code = main(args)
    except SystemExit as stop:
        code = int(stop.code or 0)
    captured = capsys.readouterr()
    assert code == 2
    lines = [line for line in captured.err.splitlines() if not line.startswith("bake: ")]
    assert lines == [TOO_BIG[argv]]
    assert list(tmp_path.iterdir()) == []


# A command stopped by a signal while an object with a failing finalizer lives in its
# frames (numba's compiler stopped mid-compile leaves such objects: its OutputString's
# __del__ raised AttributeError after the stop's line, so the bake's last line was that).
_STOPPED_MID_WORK = """
import argparse, os, signal, sys
from ecs_tentacles.cli.command import _run, terminate_by_exception

class HalfBuilt:
    def __del__(self):
        raise AttributeError("'OutputString' object has no attribute '_ptr'")

def handler(args):
    half = HalfBuilt()
    {stop}

with terminate_by_exception():
    code = _run(argparse.Namespace(handler=handler, debug=False))
sys.stderr.flush()
sys.exit(code)
"""


@pytest.mark.parametrize(
    ("stop", "code", "line"),
    [
        ("raise KeyboardInterrupt", 130, "error: interrupted (Ctrl-C); partial outputs removed"),
        (
            "os.kill(os.getpid(), signal.SIGTERM)",
            143,
            "error: stopped by SIGTERM; partial outputs removed",
        ),
    ],
)
def test_a_stopped_command_ends_in_its_one_line_whatever_finalizers_fail(
    stop: str, code: int, line: str
) -> None:
    script = _STOPPED_MID_WORK.format(stop=stop)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == code, done.stderr
    assert done.stderr.strip().splitlines() == [line]
