"""Gait clips kept between runs: a morphology's recording read back instead of made again.

    key = entry_key(recording_input(creature, physics))   # what the clips are made from
    keep(key, clips)          # writes <cache_folder()>/<key>.clips, whole or not at all
    clips = read(key, shape)  # the clips, or None: absent or not to be trusted

Recording a morphology's clips steps it alone for 20 simulated seconds (about 2.5 s of
wall clock for the 8 x 10 octopus, per morphology), on the first frame a crowd replays
anyone: a 1,024 crowd's first frame of `run` waited for it every run. The entry's key is
the SHA-256 of what the recording is made from (the creature's staged scene,
`cache.recording_input`), the recording's lengths, the MuJoCo and numpy versions and
every source file of this package (so a change of the code that moves a creature
records anew). Reads and writes only `cache_folder()`: `$XDG_CACHE_HOME/ecs_tentacles/
clips`, else `~/.cache/ecs_tentacles/clips`.

Nothing in an entry is trusted (as the mesh cache's, `ecs_tentacles.terrain.mesh_cache`):
only a regular file of at most `MAX_ENTRY_BYTES` is read (not followed if a link, never
waited on), only fixed-size integers and float64 numbers are decoded (no zip, pickle or
JSON parser sees it), the entry names its key and ends with a SHA-256 of everything
before it, and its clips must fit the creature they are read for (`shape`: bodies,
joint coordinates, the frame's length): frame counts within the recording's, finite
numbers, unit quaternions, bodies within `MAX_METRES` of the ground frame's origin,
speed within `MAX_CRAWL_SPEED`. A forged entry can therefore show a creature moving
oddly, within those bounds, never crash a run; an entry that fails any check is ignored
as if absent (recorded again, and replaced).

Layout (little-endian): `MAGIC` (8 bytes) | the key (32) | bodies, nq, nv (uint32) |
seconds, store_lag (float64) | per clip, idle then crawl: frames, span first, span end
(uint32), dt, speed, mismatch (float64), pos, quat, qpos, qvel (float64, C order) |
SHA-256 of all the bytes before (32).
"""

from __future__ import annotations

import hashlib
import pathlib
import struct
from collections.abc import Mapping
from dataclasses import dataclass

import mujoco
import numpy as np

from ecs_tentacles.clips.clips import CRAWL, KINDS, MAX_CRAWL_SPEED, Clip, GaitClips
from ecs_tentacles.untrusted.sealed_cache import DIGEST, SealedCache

MAGIC = b"ECSTCLP1"
SUFFIX = ".clips"
MAX_FRAMES = 100_000  # a clip's frames at most (a 5 s loop at 60 fps is 300)
MAX_BODIES = 4096
MAX_JOINTS = 16_384  # qpos or qvel entries
MAX_METRES = 1000.0  # a body this far from its ground frame's origin is no recording
_HEAD = len(MAGIC) + DIGEST + 3 * 4 + 2 * 8
_CLIP_HEAD = 3 * 4 + 3 * 8
MAX_ENTRY_BYTES = 64 << 20  # far above a real entry (the octopus: about 1 MB)
CACHE = SealedCache("clips", MAGIC, SUFFIX, MAX_ENTRY_BYTES)


@dataclass(frozen=True)
class Shape:
    """What a creature's clips must fit: its bodies (names, mantle first), joint
    coordinates (nq, nv) and the scene's seconds per frame."""

    bodies: list[str]
    nq: int
    nv: int
    dt: float


def cache_folder() -> pathlib.Path:
    """Where recorded clips are kept between runs."""
    return CACHE.folder()


def entry(key: str) -> pathlib.Path:
    """The file that keeps the clips of `key` (a SHA-256 in hex)."""
    return CACHE.entry(key)


_SOURCES: str | None = None


def _sources() -> str:
    """SHA-256 of every source file of this package, its systems included (once a process)."""
    global _SOURCES
    if _SOURCES is None:
        import ecs_tentacles

        digest = hashlib.sha256()
        for root in sorted({pathlib.Path(p).resolve() for p in ecs_tentacles.__path__}):
            for path in sorted(root.rglob("*.py")):
                digest.update(str(path.relative_to(root)).encode())
                digest.update(path.read_bytes())
        _SOURCES = digest.hexdigest()
    return _SOURCES


def entry_key(recording: str, options: Mapping[str, object]) -> str:
    """The key of the clips recorded from `recording` (`cache.recording_input`) with
    `options` (`GaitClips.record`'s keywords) by this code and these libraries."""
    parts = [
        MAGIC.decode(),
        recording,
        repr(sorted(options.items())),
        mujoco.__version__,
        np.__version__,
        _sources(),
    ]
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()


def encode(key: str, clips: GaitClips) -> bytes:
    """The entry's bytes for `clips` under `key`."""
    return CACHE.seal(key, _payload(clips))


def _payload(clips: GaitClips) -> bytes:
    """What an entry holds after the key: the sizes, then each clip's head and arrays."""
    idle, crawl = clips.idle, clips.crawl
    nq, nv = idle.qpos.shape[1], idle.qvel.shape[1]
    parts = [struct.pack("<3I2d", len(clips.bodies), nq, nv, clips.seconds, clips.store_lag)]
    for clip in (idle, crawl):
        first, end = clip.span
        parts.append(
            struct.pack("<3I3d", clip.frames, first, end, clip.dt, clip.speed, clip.mismatch)
        )
        for array in (clip.pos, clip.quat, clip.qpos, clip.qvel):
            parts.append(np.ascontiguousarray(array, dtype="<f8").tobytes())
    return b"".join(parts)


def decode(key: str, data: bytes, shape: Shape, morphology: tuple[object, ...]) -> GaitClips | None:
    """The clips in an entry's bytes, or None unless every check holds (module doc)."""
    body = CACHE.opened(key, data, _HEAD - CACHE.head + 2 * _CLIP_HEAD)
    if body is None:
        return None
    bodies, nq, nv, seconds, lag = struct.unpack_from("<3I2d", body, CACHE.head)
    if (bodies, nq, nv) != (len(shape.bodies), shape.nq, shape.nv):
        return None
    if not (0 < bodies <= MAX_BODIES and 0 < nq <= MAX_JOINTS and 0 < nv <= MAX_JOINTS):
        return None
    offset, made = _HEAD, []
    for kind in KINDS:
        if offset + _CLIP_HEAD > len(body):
            return None
        frames, first, end, dt, speed, mismatch = struct.unpack_from("<3I3d", body, offset)
        offset += _CLIP_HEAD
        if not 2 <= frames <= MAX_FRAMES or end - first != frames or dt != shape.dt:
            return None
        sizes = [frames * bodies * 3, frames * bodies * 4, frames * nq, frames * nv]
        if offset + 8 * sum(sizes) > len(body):
            return None
        arrays = []
        for size in sizes:
            arrays.append(np.frombuffer(body, "<f8", size, offset).astype(np.float64))
            offset += 8 * size
        pos, quat = arrays[0].reshape(frames, bodies, 3), arrays[1].reshape(frames, bodies, 4)
        qpos, qvel = arrays[2].reshape(frames, nq), arrays[3].reshape(frames, nv)
        speed_ok = 0.0 <= speed <= MAX_CRAWL_SPEED and (speed == 0.0 or kind == KINDS[CRAWL])
        if not (speed_ok and 0.0 <= mismatch <= MAX_METRES and _sane(pos, quat, qpos, qvel)):
            return None
        made.append(Clip(kind, dt, speed, pos, quat, qpos, qvel, mismatch, (first, end)))
    if offset != len(body) or not (0.0 <= seconds and np.isfinite(lag)):
        return None
    return GaitClips(morphology, list(shape.bodies), made[0], made[1], seconds, lag, kept=True)


def _sane(pos: np.ndarray, quat: np.ndarray, qpos: np.ndarray, qvel: np.ndarray) -> bool:
    """Finite numbers, unit quaternions and bodies within `MAX_METRES` of the origin."""
    if not all(bool(np.isfinite(a).all()) for a in (pos, quat, qpos, qvel)):
        return False
    unit = np.abs(np.einsum("fbi,fbi->fb", quat, quat) - 1.0) < 1e-6
    return bool(unit.all() and (np.abs(pos) <= MAX_METRES).all())


def read(key: str, shape: Shape, morphology: tuple[object, ...]) -> GaitClips | None:
    """The clips kept under `key` for a creature of `shape` (its physics `morphology`
    key), or None: absent, not a regular file, too large, unreadable or failing a check."""
    data = CACHE.load(key)
    return None if data is None else decode(key, data, shape, morphology)


def keep(key: str, clips: GaitClips) -> None:
    """Write `clips` as the entry of `key`, atomically (`atomic_file`); a cache that
    cannot be written is skipped silently (the next run records again)."""
    CACHE.keep(key, _payload(clips))
