"""step_frames: every frame run, in tenth-of-a-second chunks, a bar only when asked."""

from __future__ import annotations

import io
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from ecs_tentacles.output.progress import step_frames
from ecs_tentacles.world import World
from tests.conftest import creature_scene
from tests.terminal import drawn_until_closed, on_a_terminal


class Terminal(io.StringIO):
    """A captured stderr that says it is a terminal, as tqdm wants before it draws."""

    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize(("fps", "frames", "chunks"), [(60, 14, [6, 6, 2]), (20, 5, [2, 2, 1])])
def test_steps_every_frame_in_chunks(
    make_world: Callable[..., World], fps: int, frames: int, chunks: list[int]
) -> None:
    scene = creature_scene(count=2, links=2) | {"physics": {"fps": fps, "substeps": 24}}
    world = make_world(scene)
    told: list[int] = []
    step_frames(world, frames, progress=False, on_steps=told.append)
    assert (world.frame, told) == (frames, chunks)


@pytest.mark.parametrize("progress", [True, False])
def test_the_bar_is_drawn_only_with_progress(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch, progress: bool
) -> None:
    world = make_world(creature_scene(count=2, links=2))
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    step_frames(world, 12, progress=progress, desc="bake")
    drawn = terminal.getvalue()
    assert ("bake:" in drawn and "/12 [" in drawn) == progress
    assert drawn == "" or progress


@pytest.mark.parametrize("terminal", [True, False])
def test_long_commands_say_what_they_are_doing_on_a_terminal(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, terminal: bool
) -> None:
    from ecs_tentacles.cli import main

    err: io.StringIO = Terminal() if terminal else io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    monkeypatch.setattr("ecs_tentacles.output.progress.LONG_SECONDS", 0.0)  # keep every line
    out = tmp_path / "crowd.json"
    assert main(["crowd", "8", "--out", str(out)]) == 0
    assert main(["validate", str(out)]) == 0
    assert main(["run", str(out), "--frames", "2"]) == 0
    shown = err.getvalue()
    for doing in ("crowd: making and checking 8 creatures ...", f"validate: checking {out} ...",
                  f"run: building {out} ..."):  # fmt: skip
        assert (doing in shown) == terminal, (doing, shown)


def _on_a_terminal(args: list[str], cwd: Path) -> tuple[int, str, str]:
    """Run `ecs-tentacles ARGS` with stderr on a pseudo-terminal, as from a shell:
    (exit code, stdout, everything drawn on the terminal)."""
    process, main = on_a_terminal(args, cwd)
    drawn = drawn_until_closed(main)
    out, _ = process.communicate(timeout=300)
    return process.returncode, out.decode(), drawn


@pytest.fixture(scope="module")
def small_take(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from ecs_tentacles.export.bake import BakePlan, bake

    path = tmp_path_factory.mktemp("take") / "octopus.npz"
    bake(BakePlan.make("octopus", seconds=0.2, fps=30), progress=False).save(path)
    return path


EXPORT = ["export", "{take}", "--out"]
BAKE = ["bake", "octopus", "--seconds", "0.2", "--out", "x.npz"]


@pytest.mark.parametrize(
    ("args", "lines"),
    [
        ([*EXPORT, "x.glb"], ["export: reading", "write x.glb:", "/1 [", "creature"]),
        ([*EXPORT, "x.glb", "--rigid"], ["write x.glb:", "/81 [", "body"]),
        ([*EXPORT, "x.usda"], ["write x.usda:", "frame"]),  # USD streams: frames
        # a take is written as the bake goes: its bar is the bake's, then the last chunk
        (BAKE, ["bake: building the world", "/12 [", "bake: writing x.npz"]),
    ],
    ids=["skinned glb", "rigid glb", "skinned usd", "take"],
)
def test_writing_shows_a_bar_on_a_terminal_and_nothing_with_quiet(
    small_take: Path, tmp_path: Path, args: list[str], lines: list[str]
) -> None:
    args = [arg.format(take=small_take) for arg in args]
    code, out, drawn = _on_a_terminal(args, tmp_path)
    assert code == 0, drawn
    for line in lines:
        assert line in drawn, (line, drawn)
    assert "x." in out  # the summary, on stdout
    code, out, drawn = _on_a_terminal([*args, "--quiet"], tmp_path)
    assert code == 0 and not any(line in drawn for line in lines), drawn
    assert "\r" not in drawn.replace("\r\n", "")  # nothing redrawn: no bar, no status
    if args[0] == "export":
        assert drawn == ""
