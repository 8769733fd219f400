"""How the slow docs tier runs a line that opens the sandbox's window (`ecs-tentacles play
SCENE` without `--headless`): as a person would, on a virtual X display.

A block whose marker says "virtual X display" gets an X server of its own (Xvfb, its
display number chosen by the server: `-displayfd`); each window line runs until its
window (caption `ecs_tentacles`) is shown, plays for `PLAYING` seconds, then is sent
F12 (the sandbox saves `ecs_tentacles_001.png` in the folder it runs in) and Ctrl+Q
(it quits as its close button does), both as key presses through X (xdotool). The line
must exit 0 within `QUITTING` seconds of Ctrl+Q, print no traceback, and the screenshot
must be a picture of the window's size that is not one flat colour. Without Xvfb and
xdotool (`apt-get install xvfb xdotool`) the block is skipped, saying so.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

CAPTION = "ecs_tentacles"  # the sandbox window's (render/sandbox.py)
SCREENSHOT = "ecs_tentacles_001.png"  # F12's first picture in a run (render/sandbox_picture.py)
SHOWN = 300  # seconds a window may take to show (a level's world is built first)
PLAYING = 8  # seconds the sandbox runs before F12
SAVED = 120  # seconds F12's picture may take to appear
QUITTING = 60  # seconds from Ctrl+Q to the exit


def opens_window(argv: list[str]) -> bool:
    """True for `ecs-tentacles play ...` without `--headless`."""
    return argv[:2] == ["ecs-tentacles", "play"] and "--headless" not in argv


@contextlib.contextmanager
def virtual_display(env: dict[str, str]) -> Iterator[str]:
    """An X server of the block's own (it carries the block's environment, so it is ended
    with the block's processes too); yields its DISPLAY."""
    missing = [tool for tool in ("Xvfb", "xdotool") if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"{' and '.join(missing)} not found (apt-get install xvfb xdotool)")
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
        pass_fds=(write,),
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write)
    with os.fdopen(read) as said:
        number = said.readline().strip()
    try:
        assert number.isdigit(), f"Xvfb gave no display number (exit {server.poll()})"
        yield f":{number}"
    finally:
        server.terminate()
        server.wait(timeout=30)


def xdotool(env: dict[str, str], *words: str, timeout: float = 30) -> str:
    done = subprocess.run(
        ["xdotool", *words], env=env, capture_output=True, text=True, timeout=timeout, check=True
    )
    return done.stdout


def shown_window(process: subprocess.Popen[bytes], env: dict[str, str], what: str,
                 log: Path) -> str:  # fmt: skip
    """The id of the sandbox's window once it shows; fails (with what the line printed)
    if the line ends first or the window takes over `SHOWN` seconds."""
    deadline = time.monotonic() + SHOWN
    while time.monotonic() < deadline:
        assert process.poll() is None, f"{what} ended before its window showed:\n{log.read_text()}"
        found = subprocess.run(
            ["xdotool", "search", "--onlyvisible", "--name", f"^{CAPTION}$"],
            env=env, capture_output=True, text=True, timeout=30, check=False,
        )  # fmt: skip
        if found.stdout.split():
            return found.stdout.split()[0]
        time.sleep(0.5)
    raise AssertionError(f"{what}: no window in {SHOWN} s:\n{log.read_text()}")


def run_window(command: str, size: tuple[int, int], folder: Path, env: dict[str, str],
               where: str) -> None:  # fmt: skip
    """Run a window line as the module's docstring says, and check what it left."""
    picture = folder / SCREENSHOT
    picture.unlink(missing_ok=True)
    log = folder / "window.log"
    with log.open("w") as out:
        process = subprocess.Popen(
            ["bash", "-c", command], cwd=folder, env=env, stdout=out, stderr=subprocess.STDOUT
        )
    try:
        window = shown_window(process, env, f"{where}: `{command}`", log)
        time.sleep(PLAYING)
        assert process.poll() is None, f"{where}: `{command}` ended by itself:\n{log.read_text()}"
        xdotool(env, "key", "--window", window, "F12")
        deadline = time.monotonic() + SAVED
        while f"saved {SCREENSHOT}" not in log.read_text() and time.monotonic() < deadline:
            time.sleep(0.5)
        xdotool(env, "key", "--window", window, "ctrl+q")
        code = process.wait(timeout=QUITTING)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    said = log.read_text()
    assert code == 0, f"{where}: `{command}` exited {code} after Ctrl+Q:\n{said}"
    assert "Traceback" not in said, f"{where}: `{command}` printed a traceback:\n{said}"
    assert picture.is_file(), f"{where}: F12 saved no {SCREENSHOT}:\n{said}"
    with Image.open(picture) as image:
        pixels = np.asarray(image.convert("RGB"))
    assert pixels.shape[1::-1] == size, f"{where}: {picture.name} is {pixels.shape[1::-1]}"
    assert np.ptp(pixels.reshape(-1, 3), axis=0).max() > 32, f"{where}: {picture.name} is flat"
