"""The worker process that turns mesh files into convex pieces (`ecs_tentacles.terrain.meshes`
runs it: `python -m ecs_tentacles.terrain.mesh_worker`, one per scene build, reused for
every mesh of it).

Reading a mesh (trimesh) and splitting it into convex pieces (CoACD) cost time and
memory that the file's size does not bound, and CoACD's C++ does not stop for signals:
here they run where the parent can stop them (a budget, SIGTERM, Ctrl-C) by killing
this process. The checks run here too, before any of that code sees the vertices:
coordinates bounded (qhull crashed on 1e300), a volume (collinear points, one triangle).

Protocol (stdin -> stdout): once its imports are done the worker writes `{"ready":
true}`; then a request is one JSON line `{"suffix": ".obj", "scale": 1.0,
"size": n, "want": "pieces"}` and then the file's n bytes; the answer one JSON line,
`{"pieces": [k, ...]}` followed by each piece's k x 3 float64 vertices, or `{"error":
"one line"}`. With `"want": "bounds"` the answer is the box of the mesh's vertices,
scaled, after the same checks: `{"bounds": [[x, y, z], [x, y, z]]}` (lowest, highest
corner; `ecs_tentacles.terrain.mesh_cache.fits` holds cached pieces to it).
"""

from __future__ import annotations

import io
import json
import sys
from typing import BinaryIO

import numpy as np

MAX_EXTENT = 1000.0  # metres from the mesh's origin to any vertex, scaled (a box's largest)
MIN_WIDTH = 1e-4  # metres across the mesh's thinnest direction (thinner: no volume)
FLAT_RATIO = 1e-6  # ... or this fraction of its widest direction
MAX_PIECES = 16  # convex pieces per concave mesh (CoACD's max_convex_hull)
MAX_PIECE_VERTICES = 256  # vertices per convex piece (CoACD decimates its hulls to it)
# CoACD's search, coarser than its defaults: a 3-box arch splits the same (4 pieces) in
# 2.6 s instead of 14 s; rocks for crawling creatures need no finer hulls
COACD = {
    "max_convex_hull": MAX_PIECES,
    "seed": 0,
    "threshold": 0.1,
    "preprocess_resolution": 30,
    "resolution": 500,
    "mcts_iterations": 60,
    "mcts_max_depth": 2,
    "decimate": True,
    "max_ch_vertex": MAX_PIECE_VERTICES,
}


class Refused(ValueError):
    """The mesh cannot be an obstacle; the message says why (one line)."""


def widths(vertices: np.ndarray) -> np.ndarray:
    """(3,) the extent of `vertices` along their principal axes, thinnest first (the
    singular directions of the centred vertices: a tilted triangle is flat whatever its
    per-axis ranges)."""
    centred = vertices - vertices.mean(axis=0)
    _, axes = np.linalg.eigh(centred.T @ centred)  # ascending: the thinnest axis first
    along = centred @ axes
    return np.asarray(along.max(axis=0) - along.min(axis=0))


def has_volume(vertices: np.ndarray) -> bool:
    """Whether `vertices` span a solid: not all on a line or a plane."""
    if len(vertices) < 4:
        return False
    width = widths(vertices)
    return bool(width[0] >= MIN_WIDTH and width[0] >= FLAT_RATIO * width[2])


def checked_vertices(vertices: np.ndarray, faces: np.ndarray, scale: float) -> np.ndarray:
    """`vertices` times `scale`, refused unless they are finite, within `MAX_EXTENT` of the
    origin and hold a volume."""
    if len(faces) == 0 or len(vertices) == 0:
        raise Refused("the file holds no triangles")
    with np.errstate(over="ignore", invalid="ignore"):
        scaled = np.asarray(vertices, dtype=np.float64) * scale
    if not np.isfinite(scaled).all():
        raise Refused("a vertex is not a finite number (times the scale)")
    far = float(np.abs(scaled).max())
    if far > MAX_EXTENT:
        raise Refused(
            f"a vertex lies {far:.3g} m from the mesh's origin (times scale {scale:g});"
            f" at most {MAX_EXTENT:g} m"
        )
    used = scaled[np.unique(faces)] if faces.max(initial=-1) < len(scaled) else scaled
    if len(used) < 4:
        raise Refused("the mesh has no volume (fewer than 4 vertices)")
    width = widths(used)
    if not (width[0] >= MIN_WIDTH and width[0] >= FLAT_RATIO * width[2]):
        shape = "a line" if width[1] < MIN_WIDTH else "a plane"
        raise Refused(
            f"the mesh has no volume: its vertices lie on {shape} (thinnest extent"
            f" {width[0]:.3g} m; at least {MIN_WIDTH:g} m)"
        )
    return scaled


def _loaded(data: bytes, suffix: str, scale: float) -> tuple[object, np.ndarray, np.ndarray]:
    """A mesh file's bytes -> (the trimesh object, its checked vertices scaled, faces)."""
    import trimesh

    try:
        mesh = trimesh.load(io.BytesIO(data), file_type=suffix.lstrip("."), force="mesh")
    except Exception as error:  # trimesh raises many kinds for a bad file
        message = " ".join(str(error).split())[:200] or type(error).__name__
        raise Refused(f"not a readable mesh ({message})") from None
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    return mesh, checked_vertices(vertices, faces, scale), faces


def bounds_of(data: bytes, suffix: str, scale: float) -> list[list[float]]:
    """[lowest, highest] corner of the box around a mesh file's vertices, scaled."""
    _, scaled, _ = _loaded(data, suffix, scale)
    return [scaled.min(axis=0).tolist(), scaled.max(axis=0).tolist()]


def pieces_of(data: bytes, suffix: str, scale: float) -> list[np.ndarray]:
    """The convex pieces (vertex arrays, metres) of a mesh file's bytes, scaled."""
    from scipy.spatial import ConvexHull

    mesh, scaled, faces = _loaded(data, suffix, scale)
    if getattr(mesh, "is_convex", False):
        hull = ConvexHull(scaled)
        if len(hull.vertices) <= MAX_PIECE_VERTICES:
            return [scaled[hull.vertices]]
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(scaled, faces), **COACD)
    pieces = [np.asarray(v, dtype=np.float64) for v, _ in parts]
    pieces = [p for p in pieces if np.isfinite(p).all() and has_volume(p)]
    if not pieces:
        raise Refused("no convex piece with a volume came out of its decomposition")
    return pieces


def _serve(requests: BinaryIO, answers: BinaryIO) -> None:
    answers.write(b'{"ready": true}\n')  # the imports are done: budgets start with a mesh
    answers.flush()
    while True:
        line = requests.readline()
        if not line:
            return
        request = json.loads(line)
        data = requests.read(int(request["size"]))
        suffix, scale = str(request["suffix"]), float(request["scale"])
        pieces: list[np.ndarray] = []
        try:
            if request.get("want") == "bounds":
                answer: dict[str, object] = {"bounds": bounds_of(data, suffix, scale)}
            else:
                pieces = pieces_of(data, suffix, scale)
                answer = {"pieces": [len(p) for p in pieces]}
        except Refused as refused:
            answer = {"error": str(refused)}
        except MemoryError:
            answer, pieces = {"memory": True}, []
        answers.write(json.dumps(answer).encode() + b"\n")
        for piece in pieces:
            answers.write(np.ascontiguousarray(piece, dtype="<f8").tobytes())
        answers.flush()


def _die_with_parent() -> None:
    """Linux: end this process when the parent dies (a killed farm job leaves no worker)."""
    try:
        import ctypes
        import signal

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _limit_memory(megabytes: int) -> None:
    """A backstop under the parent's watch of resident memory (`megabytes`, the budget):
    the address space may grow by at most twice that and 512 MB past what the imports
    took. Address space runs ahead of resident memory (thread stacks, glibc's 64 MB
    arenas per thread): a backstop at the budget itself could stop the worker before
    the parent saw the budget passed, and the user got "the worker stopped" instead."""
    try:
        import resource

        with open("/proc/self/statm") as handle:
            pages = int(handle.read().split()[0])
        now = pages * resource.getpagesize()
        limit = now + (2 * megabytes + 512) * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (OSError, ValueError, ImportError):
        pass


def main() -> None:
    import coacd  # noqa: F401
    import trimesh  # noqa: F401  (imported before the memory limit is taken)
    from scipy.spatial import ConvexHull  # noqa: F401

    _die_with_parent()
    if len(sys.argv) > 1:
        _limit_memory(int(sys.argv[1]))
    _serve(sys.stdin.buffer, sys.stdout.buffer)


if __name__ == "__main__":
    main()
