"""How a `<!-- slow: why -->` block of the docs runs (`pytest -m slow tests/docs`).

The block runs as written, line after line, each in `bash` from a scratch folder of its
own: a copy of the repository's files (as a clone has them: what git tracks or would
track; the lines read `assets/` and `tools/`, and `pip install -e .` the package). What
a line writes lands in that folder, never in the repository
(`--render assets/screenshots/...` overwrites the copy). `ecs-tentacles`, `python`,
`ray` and `pip` are the test's own environment's; HOME, the data folders, Blender's user
folder (`BLENDER_USER_RESOURCES`) and Ray's (`RAY_TMPDIR`: no other Ray on the machine
joins this one) are in the scratch folder; pip's download cache is the user's.

Each line must exit 0 and print no traceback. Then what it wrote is checked (the
outputs its parser names: `--out`, `--screenshot`, `--video`, `--render`): there and
not empty, and a file of its kind: a PNG an image of the size asked for, a USD a stage
pxr opens with the frames in it, a take a take the package reads, a glb, a .blend, an
MP4, a zip, JSON. A wedge's `{name}` output is one file a variant; `blender-addon
--install` and Blender's `extension install-file` leave the add-on enabled in the
scratch Blender user folder. A line that opens the sandbox's window (`play` without
`--headless`) runs on an X server of the block's own (tests/docs/windows.py).

The only words changed before a line runs are the ones `SUBSTITUTIONS` names, each
only where the block's marker says so: `/path/to/blender` and the `python` that runs
`tools/blender_import.py` are a Python with bpy 5.0.1 (`ECS_TENTACLES_BLENDER_PYTHON`;
skipped where it is not set); `blender --command extension` is Blender's own handler of
that command run in that Python; `HEAD_IP` (a Ray cluster's head) is 127.0.0.1. Where
the marker says "a Python with bpy on the PATH as `blender`", the block's PATH has a
`blender` that runs that Python. A block that two pages show runs once. The processes a
block leaves behind (a local Ray's, a Ray cluster's, the X server) are ended by their
ids: those whose environment holds the block's own token.
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zipfile
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ecs_tentacles.distributed.wedge import parse_parameter
from ecs_tentacles.take.read import read_take
from tests.docs.parsed import WRITES, chained, parse, tool, values
from tests.docs.windows import opens_window, run_window, virtual_display

ROOT = Path(__file__).resolve().parents[2]
BPY = "ECS_TENTACLES_BLENDER_PYTHON"
TIMEOUT = 3600  # seconds a line may take (the herding bot plays three levels)


def blender_python() -> str:
    found = os.environ.get(BPY)
    if not found:
        pytest.skip(f"{BPY} is not set (a Python with bpy 5.0.1, as CI makes)")
    return found


# Blender's own `extension` command (`blender --command extension ...`), as Blender runs it:
# the handler its bundled extensions add-on registers, in Blender as a module
EXTENSION_COMMAND = (
    "import sys, bpy; from bl_pkg import bl_extension_cli as cli;"
    " sys.exit(cli.cli_extension_handler(sys.argv[1:]))"
)

# (what the line says, what runs in its place (shell words), what the block's marker
# must say for it)
SUBSTITUTIONS: tuple[tuple[re.Pattern[str], Callable[[], str], str], ...] = (
    (
        re.compile(r"/path/to/blender\b"),
        lambda: shlex.quote(blender_python()),
        "a Python with bpy",
    ),
    (
        re.compile(r"^python(?= tools/blender_import\.py)"),
        lambda: shlex.quote(blender_python()),
        "a Python with bpy",
    ),
    (
        re.compile(r"^blender --command extension\b"),
        lambda: f"{shlex.quote(blender_python())} -c {shlex.quote(EXTENSION_COMMAND)}",
        "Blender's own extension command in a Python with bpy",
    ),
    (re.compile(r"\bHEAD_IP\b"), lambda: "127.0.0.1", "HEAD_IP is 127.0.0.1"),
)
ON_PATH = "a Python with bpy on the PATH as `blender`"  # the marker's words for that
WINDOWS = "virtual X display"  # the marker's words for window lines (tests/docs/windows.py)


def substituted(line: str, reason: str, where: str) -> str:
    for pattern, replacement, said in SUBSTITUTIONS:
        while found := pattern.search(line):
            assert said in reason, f"{where}: the marker must say {said!r} to run {line!r}"
            line = line[: found.start()] + replacement() + line[found.end() :]
    return line


def blender_on_path(folder: Path, env: dict[str, str]) -> None:
    """`blender` on the block's PATH: a script that runs the Python with bpy."""
    where = folder / "bin"
    where.mkdir()
    shim = where / "blender"
    shim.write_text(f'#!/bin/sh\nexec {shlex.quote(blender_python())} "$@"\n')
    shim.chmod(0o755)
    env["PATH"] = os.pathsep.join([str(where), env["PATH"]])


def scratch_copy(folder: Path) -> None:
    """The repository's files as they are (what git tracks or would, not what it
    ignores: no caches, no built site), copied into `folder`: a clone's."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
    ).stdout
    for name in filter(None, listed.decode().split("\0")):
        source, copy = ROOT / name, folder / name
        copy.parent.mkdir(parents=True, exist_ok=True)
        if source.is_symlink():  # a link as a link (ecs_tentacles/assets -> ../assets)
            copy.symlink_to(os.readlink(source))
        elif source.is_file():  # (not one deleted but not yet committed)
            shutil.copy2(source, copy)


@contextlib.contextmanager
def environment(folder: Path) -> Iterator[dict[str, str]]:
    """The block's environment (see the module's docstring); on leaving, every process
    still running with its token ended, by id."""
    token = f"{folder.name}-{os.getpid()}-{time.monotonic_ns()}"
    ray = Path(tempfile.mkdtemp(prefix="ray-", dir="/tmp"))  # Ray's socket paths are short
    env = dict(os.environ)
    env.update(
        PATH=os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")]),
        HOME=str(folder / "home"),
        XDG_DATA_HOME=str(folder / "data"),
        ECS_TENTACLES_DATA=str(folder / "data"),
        BLENDER_USER_RESOURCES=str(folder / "blender"),
        RAY_TMPDIR=str(ray),
        PIP_CACHE_DIR=os.environ.get("PIP_CACHE_DIR") or pip_cache(),
        ECS_TENTACLES_DOCS_BLOCK=token,
    )
    env.pop("VIRTUAL_ENV", None)
    env.pop("RAY_ADDRESS", None)
    env.pop("DISPLAY", None)  # a window line gets an X server of the block's own
    (folder / "home").mkdir()
    try:
        yield env
    finally:
        end_processes(token)
        shutil.rmtree(ray, ignore_errors=True)


def pip_cache() -> str:
    """pip's own cache folder for this user (the block's HOME is a scratch one: its
    installs download nothing the user's pip already has)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return str(Path(base) / "pip")


def processes_with(token: str) -> list[int]:
    found = []
    needle = f"ECS_TENTACLES_DOCS_BLOCK={token}".encode()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and int(entry.name) != os.getpid():
            with contextlib.suppress(OSError):
                if needle in (entry / "environ").read_bytes().split(b"\0"):
                    found.append(int(entry.name))
    return found


def end_processes(token: str) -> None:
    for sig in (signal.SIGTERM, signal.SIGKILL):
        pids = processes_with(token)
        for pid in pids:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, sig)
        deadline = time.monotonic() + 15
        while pids and time.monotonic() < deadline:
            time.sleep(0.2)
            pids = processes_with(token)
        if not pids:
            return


def run_block(lines: list[str], reason: str, where: str, folder: Path) -> None:
    """Run the block's `lines` as the module's docstring says, then check their outputs."""
    scratch_copy(folder)
    started = time.time()
    with environment(folder) as env, contextlib.ExitStack() as display:
        if ON_PATH in reason:
            blender_on_path(folder, env)
        for line in lines:
            command = substituted(line, reason, where)
            argv = shlex.split(line, comments=True)
            if opens_window(argv):
                assert WINDOWS in reason, f"{where}: the marker must say {WINDOWS!r} for {line!r}"
                if "DISPLAY" not in env:  # the block's first window: its X server
                    env["DISPLAY"] = display.enter_context(virtual_display(env))
                run_window(command, window_size(argv, folder, where), folder, env, where)
                continue
            done = subprocess.run(
                ["bash", "-c", command],
                cwd=folder,
                env=env,
                capture_output=True,
                text=True,
                timeout=TIMEOUT,
                check=False,
            )
            said = done.stdout + done.stderr
            assert done.returncode == 0, f"{where}: `{command}` exited {done.returncode}:\n{said}"
            assert "Traceback" not in said, f"{where}: `{command}` printed a traceback:\n{said}"
            if argv[:4] == ["blender", "--command", "extension", "install-file"]:
                addon_installed(env, where, line)
            for words in chained(shlex.split(command, comments=True)):
                check_outputs(words, folder, env, started, where)


def window_size(argv: list[str], folder: Path, where: str) -> tuple[int, int]:
    """The window's size a `play` line asks for (`--width`, `--height`)."""
    from ecs_tentacles.cli import build_parser

    with contextlib.chdir(folder):
        args = parse(build_parser(), argv[1:], where)
    return args.width, args.height


def addon_installed(env: dict[str, str], where: str, line: str) -> None:
    """The add-on is in the block's Blender user folder, and the preferences were saved."""
    manifest = Path(env["BLENDER_USER_RESOURCES"]).glob(
        "extensions/user_default/ecs_tentacles_take/blender_manifest.toml"
    )
    assert list(manifest), f"{where}: `{line}` installed no add-on"
    prefs = list(Path(env["BLENDER_USER_RESOURCES"]).rglob("userpref.blend"))
    assert prefs, f"{where}: `{line}` saved no preferences"


def parser_of(argv: list[str]) -> tuple[object, list[str]] | None:
    """The parser of a project command (`ecs-tentacles`, `tools/X.py`) and its words."""
    if argv[0] == "ecs-tentacles":
        from ecs_tentacles.cli import build_parser

        return build_parser(), argv[1:]
    if len(argv) > 1 and argv[1].startswith("tools/"):
        return tool(Path(argv[1]).stem).build_parser(), argv[2:]
    return None


def check_outputs(
    argv: list[str], folder: Path, env: dict[str, str], since: float, where: str
) -> None:
    """What the command `argv` wrote (see the module's docstring)."""
    found = parser_of(argv)
    if found is None:
        return
    parser, words = found
    with contextlib.chdir(folder):
        args = parse(parser, words, where)  # type: ignore[arg-type]
    if words[:1] == ["blender-addon"] and args.install:
        addon_installed(env, where, shlex.join(argv))
    for name in values(args, WRITES):
        if "{name}" in name:  # a wedge: one file a variant
            axes = [parse_parameter(text) for text in args.wedge]
            expected = int(np.prod([len(axis.values) for axis in axes]))
            made = sorted((folder / Path(name).parent).glob(Path(name).name.replace("{name}", "*")))
            assert len(made) == expected, f"{where}: {name}: {len(made)} files, not {expected}"
        elif Path(name).suffix:
            made = [folder / name]
        else:  # a stem: the tool writes <stem>.csv, <stem>.png
            made = sorted(folder.glob(f"{name}.*"))
            assert made, f"{where}: nothing written as {name}.*"
        for path in made:
            assert path.is_file() and path.stat().st_size > 0, f"{where}: {path} not written"
            assert path.stat().st_mtime >= since, f"{where}: {path} is older than the block"
            try:
                check_file(path, args, where)
            except AssertionError:
                raise
            except Exception as error:  # a reader's refusal: the file is not of its kind
                raise AssertionError(f"{where}: {path}: {error}") from error


def check_file(path: Path, args: object, where: str) -> None:
    """`path` is a file of its kind (see the module's docstring)."""
    suffix = path.suffix.lower()
    head = path.read_bytes()[:16]
    if suffix == ".png":
        with Image.open(path) as image:
            image.load()
            size = image.size
        width, height = getattr(args, "size", None) or (
            getattr(args, "width", None),
            getattr(args, "height", None),
        )
        if width:
            assert size == (width, height), f"{where}: {path} is {size}, not {(width, height)}"
    elif suffix in (".usd", ".usdc", ".usda"):
        from pxr import Usd

        stage = Usd.Stage.Open(str(path))
        assert stage is not None, f"{where}: {path}: pxr cannot open it"
        frames = stage.GetEndTimeCode() - stage.GetStartTimeCode()
        assert frames > 0 and len(list(stage.Traverse())) > 1, f"{where}: {path} is empty"
    elif suffix == ".npz":
        header, _ = read_take(path, header_only=True)
        assert header["frames"] > 1, f"{where}: {path}: {header['frames']} frames"
    elif suffix == ".glb":
        assert head[:4] == b"glTF", f"{where}: {path} is not a glb"
    elif suffix == ".blend":
        zstd = head[:4] == b"\x28\xb5\x2f\xfd"  # Blender 5 compresses its files
        assert head[:7] == b"BLENDER" or zstd, f"{where}: {path} is not a .blend"
    elif suffix == ".mp4":
        assert head[4:8] == b"ftyp" and path.stat().st_size > 10_000, f"{where}: {path}"
    elif suffix == ".zip":
        with zipfile.ZipFile(path) as archive:
            assert archive.testzip() is None, f"{where}: {path} is a broken zip"
    elif suffix == ".json":
        json.loads(path.read_text())
    elif suffix == ".csv":  # a table of runs: none failed (a failed run keeps its error)
        with path.open(newline="") as rows:
            table = list(csv.DictReader(rows))
        failed = [row for row in table if row.get("error")]
        assert table and not failed, f"{where}: {path}: {len(table)} rows, failed: {failed}"
