"""Shared fixtures: fresh worlds from small scenes, closed after each test."""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from ecs_tentacles.world import World

# plugins off where a test's script drives the motors: `make_world(scene, plugins=NO_LOCOMOTION)`
NO_LOCOMOTION = {"locomotion": False, "suckers": False}


def worlds_by_backend(
    make_world: Callable[..., World],
    kernels: Any,
    monkeypatch: pytest.MonkeyPatch,
    scene: dict[str, Any],
    frames: int,
) -> list[World]:
    """`scene` stepped `frames` frames twice: with `kernels` (an `OptionalKernels`) on
    numba's path, then on numpy's; the two worlds, in that order."""
    worlds = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(kernels, "backend", backend)
        world = make_world(scene)
        world.step(frames)
        worlds.append(world)
    return worlds


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


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Decomposed meshes are cached in a folder of the test session's own, not the user's
    (`ecs_tentacles.terrain.mesh_cache.cache_folder`); the CLI processes tests start inherit it."""
    import os

    before = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if before is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = before


@pytest.fixture(scope="session", autouse=True)
def _private_state(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """The key work shards are signed with is made in a folder of the test session's own,
    not the user's (`ecs_tentacles.distributed.secret`); CLI processes inherit it."""
    import os

    before = os.environ.get("XDG_STATE_HOME")
    os.environ["XDG_STATE_HOME"] = str(tmp_path_factory.mktemp("state"))
    yield
    if before is None:
        os.environ.pop("XDG_STATE_HOME", None)
    else:
        os.environ["XDG_STATE_HOME"] = before
