"""Shared fixtures: fresh worlds from small scenes, closed after each test."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import settings

from ecs_tentacles.world import World

# Property tests draw the same examples every run (seeded from each test's name), so what
# fails in CI fails again on a developer's machine, and 60 of them where a test does not
# say how many; `pytest --hypothesis-profile thorough` draws 1,000 new ones each run.
settings.register_profile("seeded", derandomize=True, database=None, max_examples=60)
settings.register_profile("thorough", max_examples=1000)
settings.load_profile("seeded")

# numba compiles each `cache=True` kernel on first call and keeps it on disk; on a fresh
# clone every xdist worker would compile the same kernels again. The controller compiles
# them once first, one process per worker, and the workers load them from the cache.
NUMBA_WARMUP = Path(__file__).resolve().parents[1] / "tools" / "numba_warmup.py"


@pytest.hookimpl(tryfirst=True)  # before xdist's own, which reads `-n`
def pytest_cmdline_main(config: pytest.Config) -> None:
    """The suite runs on every core: `-n auto` unless `-n` was given, where xdist is
    loaded (it is not in addopts: a run with `-p no:xdist`, or without xdist installed,
    would stop at "unrecognized arguments: -n"). Not on a worker (xdist clears its `-n`)."""
    if hasattr(config, "workerinput") or not config.pluginmanager.has_plugin("xdist"):
        return
    if config.option.numprocesses is None:
        config.option.numprocesses = "auto"


def keep_bytecode(config: pytest.Config) -> None:
    """Python's compiled bytecode kept for the session, in its temporary folder
    (`PYTHONPYCACHEPREFIX`), also where the environment says not to write it
    (`PYTHONDONTWRITEBYTECODE`): else every xdist worker, every command a test starts and
    every Ray or mesh worker compiles the package's sources again (0.4 CPU-s of a 0.8 s
    `validate`) and each worker rewrites every test module again (collection: 9.5 CPU-s
    a worker, 4 with it). Under the session's folder, not beside the sources: nothing is
    written in the tree, nor in a folder a test lists (a plugin a scene imports). Set on
    the controller before the workers start: they and the processes they start inherit
    it."""
    factory = getattr(config, "_tmp_path_factory", None)  # none with `-p no:tmpdir`
    if factory is None:
        return
    folder = factory.getbasetemp() / "pycache"
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    os.environ["PYTHONPYCACHEPREFIX"] = str(folder)
    sys.dont_write_bytecode = False
    sys.pycache_prefix = str(folder)


@pytest.hookimpl(trylast=True)  # after the terminal's, which it writes to
def pytest_configure(config: pytest.Config) -> None:
    """On the xdist controller, before any worker starts: `--dist worksteal` unless a
    `--dist` was given (a worker out of tests takes the other's last ones, so one long
    test does not leave a core idle), and the kernels the suite calls compiled into
    numba's cache (`tools/numba_warmup.py`), split over the workers' cores."""
    if not hasattr(config, "workerinput"):
        keep_bytecode(config)
    given = any(str(arg).startswith("--dist") for arg in config.invocation_params.args)
    if getattr(config.option, "dist", None) == "load" and not given:
        config.option.dist = "worksteal"  # read when the scheduler is made, at session start
    workers = getattr(config.option, "numprocesses", None) or 0
    if hasattr(config, "workerinput") or not isinstance(workers, int) or workers < 1:
        return
    if config.getoption("collectonly") or config.getoption("help"):
        return
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="numba-claims-") as claims:
        command = [sys.executable, str(NUMBA_WARMUP), "compile", "--claims", claims]
        runs = [
            subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            for _ in range(min(workers, os.cpu_count() or 1))
        ]
        said = [run.communicate()[0].strip().splitlines() or [""] for run in runs]
    failed = [lines[-1] for run, lines in zip(runs, said, strict=True) if run.returncode]
    line = (
        f"numba kernels compiled ahead by {len(runs)} processes in "
        f"{time.perf_counter() - start:.1f} s: " + "; ".join(lines[-1] for lines in said)
    )
    reporter = config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:  # shown under -q too: a stale list shows in CI's log
        reporter.write_line(line + (f" (failed: {failed[0]})" if failed else ""))


# The files whose tests hold a worker longest (a local Ray, processes started and waited
# for), run first: they are at the head of the first worker's queue while the other worker
# takes the many short tests, and worksteal hands out the short ones left at the end (a
# worker steals from the end of the other's queue), so the run does not end with one
# worker idle while the other still waits on one of these.
FIRST = (
    "distributed/test_driver.py",
    "test_processes.py",
    "export/test_glb_size.py",
    "export/test_usd_stream.py",
    "test_stops.py",
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """`FIRST`'s files ahead of the rest, in that order; every file's tests stay together
    and in their order (module fixtures are made once a worker)."""
    here = Path(__file__).parent

    def rank(item: pytest.Item) -> int:
        path = item.path
        name = path.relative_to(here).as_posix() if path.is_relative_to(here) else ""
        return FIRST.index(name) if name in FIRST else len(FIRST)

    items.sort(key=rank)  # stable


# plugins off where a test's script drives the motors: `make_world(scene, plugins=NO_LOCOMOTION)`
NO_LOCOMOTION = {"locomotion": False, "suckers": False}


# what a stopped command exits with and says last: (signal, exit code, its one line)
STOPS = [
    (signal.SIGINT, 130, "error: interrupted (Ctrl-C); partial outputs removed"),
    (signal.SIGTERM, 143, "error: stopped by SIGTERM; partial outputs removed"),
]


def python_calls(action: Callable[[], object]) -> int:
    """Python function calls (and generator resumptions) made while `action` runs: how
    the work grows with a problem's size, counted rather than timed (no noise)."""
    count = 0

    def profile(frame: object, event: str, arg: object) -> None:
        nonlocal count
        count += event == "call"

    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
    return count


def creature_scene(**tentacles: Any) -> dict[str, Any]:
    """A one-creature scene dict with the given tentacle settings."""
    return {
        "version": 1,
        "creatures": [{"name": "octo", "position": [0, 0], "tentacles": tentacles}],
    }


def crawlers(n: int, *, apart: float = 3.0, links: int = 4, ahead: float = 1.5) -> dict[str, Any]:
    """`n` small creatures (3 tentacles of `links` links) `apart` m apart in a row along
    x, each crawling to a goal `ahead` m along +y: a scene whose creatures never touch."""
    return {
        "version": 1,
        "creatures": [
            {
                "name": f"c{i}",
                "position": [apart * i, 0.0],
                "tentacles": {"count": 3, "links": links},
                "goals": [{"position": [apart * i, ahead]}],
            }
            for i in range(n)
        ],
    }


def uniform_crowd(path: Path, count: int, lod: dict[str, Any], *options: str) -> Path:
    """`ecs-tentacles crowd COUNT --uniform OPTIONS` written to `path` (in a process of its
    own, as a user runs it), its level of detail then set to `lod`; `path`."""
    subprocess.run(
        [sys.executable, "-P", "-m", "ecs_tentacles", "crowd", str(count), "--uniform",
         *options, "--out", str(path)],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    scene: dict[str, Any] = json.loads(path.read_text())
    scene.setdefault("physics", {})["lod"] = lod
    path.write_text(json.dumps(scene))
    return path


def baked(scene: str, out: Path, seconds: float, fps: float = 30.0) -> Path:
    """`ecs-tentacles bake SCENE --seconds SECONDS --fps FPS --out OUT`; `out`."""
    from ecs_tentacles.cli import main

    argv = ["bake", scene, "--seconds", str(seconds), "--fps", str(fps), "--quiet"]
    assert main([*argv, "--out", str(out)]) == 0
    return out


@pytest.fixture
def make_world() -> Iterator[Callable[..., World]]:
    """Build worlds from scene dicts; every world is closed at the end of the test."""
    worlds: list[World] = []

    def make(scene: dict[str, Any], **kwargs: Any) -> World:
        world = World.from_scene(scene, **kwargs)
        worlds.append(world)
        return world

    yield make
    for world in worlds:
        world.close()


# (kernels, scene, frames) -> the two worlds: see `worlds_by_backend`
ByBackend = Callable[[Any, dict[str, Any], int], list[World]]


@pytest.fixture
def worlds_by_backend(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> ByBackend:
    """`(kernels, scene, frames)`: `scene` stepped `frames` frames twice, with `kernels`
    (an `OptionalKernels`) on numba's path, then on numpy's; every body must stand where
    it stood the other way, bit for bit. The two worlds, in that order."""

    def both(kernels: Any, scene: dict[str, Any], frames: int) -> list[World]:
        worlds = []
        for backend in ("auto", "numpy"):
            monkeypatch.setattr(kernels, "backend", backend)
            world = make_world(scene)
            world.step(frames)
            worlds.append(world)
        np.testing.assert_array_equal(worlds[0].transforms.pos, worlds[1].transforms.pos)
        return worlds

    return both


@pytest.fixture
def ctrl_c_reaches_children() -> Iterator[None]:
    """Processes the test starts take Ctrl-C (SIGINT) as from a terminal, also when this
    run was started in the background: a shell then ignores SIGINT for it, children
    inherit that, and Python leaves an ignored SIGINT ignored (the bake never stops)."""
    ignored = signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    if ignored:
        signal.signal(signal.SIGINT, signal.default_int_handler)  # reset to default on exec
    yield
    if ignored:
        signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.fixture(scope="session")
def octopus_take() -> Any:
    """4 s of the bundled octopus scene at 30 fps (121 frames), baked once per session."""
    from ecs_tentacles.export.bake import BakePlan, bake

    return bake(BakePlan.make("octopus", seconds=4.0, fps=30.0), progress=False)


def session_folder(factory: pytest.TempPathFactory) -> Path:
    """The test session's temporary folder, the same for all its xdist workers (each
    worker's own is inside it)."""
    base = factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def once_a_session(
    factory: pytest.TempPathFactory, name: str, make: Callable[[Path], Path]
) -> Path:
    """`make(folder)`'s file, made once a session in the folder `name` (the session's,
    shared by its workers): the first worker to ask makes it, the others wait for it (a
    lock) and take the file it made. For files the tests read and never change."""
    base = session_folder(factory)
    folder, made = base / name, base / name / ".made"
    with open(base / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not made.exists():  # not yet, or the worker making it failed: from scratch
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            made.write_text(make(folder).relative_to(folder).as_posix())
    return folder / made.read_text()


def _own_folder(variable: str, folder: Path) -> Iterator[None]:
    """The environment variable `variable` set to `folder` while the session runs (and
    in the CLI processes tests start), put back after."""
    before = os.environ.get(variable)
    os.environ[variable] = str(folder)
    yield
    if before is None:
        os.environ.pop(variable, None)
    else:
        os.environ[variable] = before


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Decomposed meshes and gait clips are cached in a folder of the test session's own,
    not the user's (`ecs_tentacles.terrain.mesh_cache.cache_folder`,
    `ecs_tentacles.clips.disk`): one folder for all xdist workers (each worker's
    temporary folder is in the session's), so a morphology's clips are recorded once a
    session, not once a worker. Entries are written whole or not at all, and a test
    about the cache itself gives it a folder of its own."""
    folder = session_folder(tmp_path_factory) / "cache"
    folder.mkdir(exist_ok=True)
    yield from _own_folder("XDG_CACHE_HOME", folder)


@pytest.fixture(scope="session", autouse=True)
def _private_state(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """The key work shards are signed with is made in a folder of the test session's own,
    not the user's (`ecs_tentacles.distributed.secret`)."""
    yield from _own_folder("XDG_STATE_HOME", tmp_path_factory.mktemp("state"))
