"""Mesh obstacles: a mesh file next to the scene -> its convex pieces, within a budget.

    with MeshReader(folder) as reader:
        pieces = reader.pieces("rock.obj", scale, json_path)   # (k, 3) arrays, metres

Each distinct file (by content, suffix and scale) is read and decomposed once: the
pieces are kept for the rest of the process and in the user's cache folder
(`ecs_tentacles.terrain.mesh_cache`: `$XDG_CACHE_HOME/ecs_tentacles/meshes`, else
`~/.cache/...`), so a thousand references to one rock, and the `run` after a `validate`,
cost one decomposition. A cached entry is read as untrusted (a regular file of bounded
size whose digests check, pieces with a volume) and used only if its pieces lie within
the mesh file's own box, which the worker reads within the same budgets as a
decomposition; any other entry is ignored, and the mesh decomposed and kept again.

The reading, the checks (finite coordinates within `MAX_EXTENT` of the mesh's origin,
a volume) and CoACD run in a worker process (`ecs_tentacles.terrain.mesh_worker`) that
this process watches and kills when a mesh takes longer than `MESH_SECONDS` or more
resident memory than `MESH_MEMORY_MB`, when the scene's meshes together take longer
than `SCENE_MESH_SECONDS`, or when this process is interrupted (SIGTERM, Ctrl-C).
Every refusal is a `TerrainError` naming the obstacle's `file` field.

Budgets (defaults; a concave rock of a few thousand triangles takes 1-3 s and under
300 MB): 60 s and 1024 MB per mesh, 300 s for all of a scene's meshes not yet cached.

The worker ends with the scene build, except inside `one_worker()`: there the builds
hand an idle worker on to the next one, and it ends with the block (`validate` of many
scenes starts one worker, not one a scene: its imports take about 1 CPU-second).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import pathlib
import select
import subprocess
import time
from collections.abc import Iterator
from typing import IO

import numpy as np

from ecs_tentacles import stops
from ecs_tentacles.processes import python_module
from ecs_tentacles.scene.load import MAX_SCENE_BYTES
from ecs_tentacles.terrain import mesh_cache, mesh_worker
from ecs_tentacles.terrain.heights import TerrainError, beside_scene, read_found
from ecs_tentacles.untrusted.files import ClosedOnExit

MESH_SECONDS = 60.0  # per mesh: reading, checks and decomposition
MESH_MEMORY_MB = 1024  # the worker's resident memory while it works on one mesh
SCENE_MESH_SECONDS = 300.0  # all of one scene's meshes that are not cached yet
MESH_SUFFIXES = (".obj", ".stl", ".glb")
MAX_MESH_BYTES = MAX_SCENE_BYTES  # the same cap as a scene file
CACHE_VERSION = 1  # part of every cache key: bump when the pieces a file gives change
START = 60.0  # seconds the worker may take to start (its imports), not part of a budget
POLL = 0.05  # seconds between looks at the worker's time and memory

JsonPath = tuple[str | int, ...]
_KNOWN: dict[str, tuple[np.ndarray, ...] | str] = {}  # key -> pieces or the refusal
_IDLE: list[_Worker] | None = None  # inside `one_worker()`: the idle worker kept, if any


def _key(data: bytes, suffix: str, scale: float) -> str:
    h = hashlib.sha256(data)
    settings = {
        "suffix": suffix,
        "scale": repr(float(scale)),
        "coacd": _coacd_version(),
        "settings": mesh_worker.COACD,
        "checks": [mesh_worker.MAX_EXTENT, mesh_worker.MIN_WIDTH, mesh_worker.FLAT_RATIO],
        "version": CACHE_VERSION,
    }
    h.update(json.dumps(settings, sort_keys=True).encode())
    return h.hexdigest()


@functools.cache
def _coacd_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("coacd")
    except PackageNotFoundError:
        return "unknown"


@contextlib.contextmanager
def one_worker() -> Iterator[None]:
    """The scene builds inside share one worker: a build's idle worker is kept for the
    next (one that is busy, over a budget or stopped is not), and ended with the block."""
    global _IDLE
    outer, _IDLE = _IDLE, []
    try:
        yield
    finally:
        kept, _IDLE = _IDLE, outer
        for worker in kept:
            worker.close()


class _Worker:
    """One worker process, fed one mesh at a time."""

    def __init__(self) -> None:
        self.busy = False  # a request sent whose whole answer is not read yet
        self.process = subprocess.Popen(
            python_module("ecs_tentacles.terrain.mesh_worker", str(MESH_MEMORY_MB)),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
        )
        self.buffer = b""
        self.ready = self._read_until(lambda: b"\n" in self.buffer, time.monotonic() + START)
        if isinstance(self.ready, bytes):
            self.buffer = self.buffer.partition(b"\n")[2]

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stdout):
            if stream is not None:
                stream.close()

    def resident_mb(self) -> float:
        """The worker's resident memory now (0 where /proc is not there)."""
        try:
            with open(f"/proc/{self.process.pid}/statm") as handle:
                pages = int(handle.read().split()[1])
        except (OSError, ValueError, IndexError):
            return 0.0
        return pages * os.sysconf("SC_PAGE_SIZE") / 1024**2

    def ask(
        self, want: str, data: bytes, suffix: str, scale: float, seconds: float
    ) -> dict[str, object]:
        """Send one mesh, for its "pieces" or "bounds"; the answer, or {"over": "time" |
        "memory" | "crash"}."""
        assert self.process.stdin is not None
        if not isinstance(self.ready, bytes):  # it did not start
            return self.ready if self.ready.get("over") != "time" else {"over": "crash"}
        request = json.dumps({"suffix": suffix, "scale": scale, "size": len(data), "want": want})
        self.busy = True
        try:
            self.process.stdin.write(request.encode() + b"\n" + data)
            self.process.stdin.flush()
        except BrokenPipeError:
            return {"over": "crash"}
        deadline = time.monotonic() + seconds
        line = self._read_until(lambda: b"\n" in self.buffer, deadline)
        if not isinstance(line, bytes):
            return line
        head, _, self.buffer = self.buffer.partition(b"\n")
        answer: dict[str, object] = json.loads(head)
        sizes = answer.get("pieces")
        if isinstance(sizes, list):
            need = 24 * sum(int(k) for k in sizes)
            body = self._read_until(lambda: len(self.buffer) >= need, deadline)
            if not isinstance(body, bytes):
                return body
            raw, self.buffer = self.buffer[:need], self.buffer[need:]
            flat = np.frombuffer(raw, dtype="<f8").reshape(-1, 3)
            cuts = np.cumsum([int(k) for k in sizes])[:-1]
            answer["arrays"] = tuple(np.array(p) for p in np.split(flat, cuts))
        self.busy = False
        return answer

    def _read_until(self, done: object, deadline: float) -> bytes | dict[str, object]:
        stdout: IO[bytes] | None = self.process.stdout
        assert stdout is not None and callable(done)
        descriptor = stdout.fileno()
        while not done():
            stops.check()  # a Ctrl-C kept while the world is built: CoACD is cut short
            left = deadline - time.monotonic()
            if left <= 0:
                return {"over": "time"}
            if self.resident_mb() > MESH_MEMORY_MB:
                return {"over": "memory"}
            ready, _, _ = select.select([descriptor], [], [], min(POLL, left))
            if ready:
                chunk = os.read(descriptor, 1 << 20)
                if not chunk:
                    return {"over": "crash"}
                self.buffer += chunk
        return b""


class MeshReader(ClosedOnExit):
    """Reads a scene's mesh files (see the module's notes); use it as a context manager,
    so its worker ends with the scene build."""

    def __init__(self, folder: pathlib.Path | None) -> None:
        self.folder = folder
        self.worker: _Worker | None = None
        self.deadline = time.monotonic() + SCENE_MESH_SECONDS
        self.over: dict[str, str] = {}  # key -> why it went over a budget (this build)

    def close(self) -> None:
        worker, self.worker = self.worker, None
        if worker is None:
            return
        if _IDLE is not None and not _IDLE and not worker.busy and worker.process.poll() is None:
            _IDLE.append(worker)  # inside `one_worker()`: the next build's
        else:
            worker.close()

    def pieces(self, name: str, scale: float, here: JsonPath) -> tuple[np.ndarray, ...]:
        """The convex pieces of mesh file `name` (next to the scene) scaled by `scale`."""
        path = beside_scene(name, self.folder, here)
        if path.suffix.lower() not in MESH_SUFFIXES:
            raise TerrainError(here, f"{name}: a mesh must be one of {', '.join(MESH_SUFFIXES)}")
        data = read_found(path, name, here, MAX_MESH_BYTES)
        suffix = path.suffix.lower()
        key = _key(data, suffix, scale)
        known = _KNOWN.get(key) or self.over.get(key)
        if known is None:
            if self.deadline - time.monotonic() <= 0:  # tried again by the next build
                raise TerrainError(here, f"{name}: {self._over_scene()}")
            known, lasting = self._read(key, data, suffix, scale)
            if not lasting and isinstance(known, str):  # over a budget: this build only
                self.over[key] = known
        if key not in self.over:
            _KNOWN[key] = known
        if isinstance(known, str):
            raise TerrainError(here, f"{name}: {known}")
        return known

    def _read(
        self, key: str, data: bytes, suffix: str, scale: float
    ) -> tuple[tuple[np.ndarray, ...] | str, bool]:
        """The pieces or why not, and whether that holds for good (not a budget's): the
        cached ones if they fit the mesh's box, else a decomposition's (then cached).
        Both asks share the mesh's budget."""
        until = min(time.monotonic() + MESH_SECONDS, self.deadline)
        kept = mesh_cache.read(key)
        if kept is not None:
            answer = self._ask("bounds", data, suffix, scale, until)
            if isinstance(answer, tuple):
                return answer
            if mesh_cache.fits(kept, np.asarray(answer["bounds"], dtype=np.float64)):
                return kept, True
        answer = self._ask("pieces", data, suffix, scale, until)
        if isinstance(answer, tuple):
            return answer
        pieces = answer["arrays"]
        assert isinstance(pieces, tuple)
        mesh_cache.keep(key, pieces)
        return pieces, True

    def _ask(
        self, want: str, data: bytes, suffix: str, scale: float, until: float
    ) -> dict[str, object] | tuple[str, bool]:
        """The worker's answer, or why there is none and whether that holds for good."""
        if self.worker is None:
            self.worker = _IDLE.pop() if _IDLE else _Worker()
        answer = self.worker.ask(want, data, suffix, scale, until - time.monotonic())
        over = answer.get("over") or ("memory" if answer.get("memory") else None)
        if over is not None or self.worker.resident_mb() > MESH_MEMORY_MB / 2:
            self.worker.close()  # a fresh worker for the next mesh (never kept)
            self.worker = None
        if over == "time":
            if until >= self.deadline:  # the scene's budget ran out first
                return self._over_scene(), False
            return (
                f"reading and splitting it into convex pieces took over {MESH_SECONDS:g} s"
                " (the budget per mesh); simplify it or split it into convex parts yourself"
            ), False
        if over == "memory":
            return (
                f"splitting it into convex pieces needed over {MESH_MEMORY_MB} MB (the"
                " budget per mesh); simplify it or split it into convex parts yourself"
            ), False
        if over == "crash":
            return "reading or splitting it into convex pieces failed (the worker stopped)", False
        if "error" in answer:
            return str(answer["error"]), True
        return answer

    @staticmethod
    def _over_scene() -> str:
        return (
            f"not read: the scene's meshes took over {SCENE_MESH_SECONDS:g} s in all (the"
            " budget per scene; meshes read before are cached, so running again goes further)"
        )
