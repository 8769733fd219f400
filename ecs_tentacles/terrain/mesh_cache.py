"""The mesh cache's files: a mesh's convex pieces kept between runs, read back as
untrusted input (`ecs_tentacles.terrain.meshes` decides when).

    keep(key, pieces)              # writes <cache_folder()>/<key>.pieces, whole or not at all
    kept = read(key)               # the pieces, or None: absent or not to be trusted
    fits(kept, box)                # every piece inside the source mesh's box (scaled)

Reads and writes only `cache_folder()`: `$XDG_CACHE_HOME/ecs_tentacles/meshes`, else
`~/.cache/ecs_tentacles/meshes`.

This package wrote the entries, but anything that can write the folder may have changed
one since (a crash or a full disk, another version, a cache shared or restored from
elsewhere, a hostile user), so nothing in an entry is trusted:
- only a regular file is read: it is opened with `O_NONBLOCK | O_NOFOLLOW` and checked
  with `fstat` before any byte is read, so a FIFO, a device, a folder or a symlink
  blocks nothing and costs nothing;
- at most `MAX_ENTRY_BYTES` are read (the largest entry a decomposition can give:
  `MAX_PIECES` pieces of `MAX_ENTRY_VERTICES`, 384 KB); a bigger file is not read at all,
  and nothing in it is decoded but fixed-size integers and float64 vertices (no zip,
  pickle or JSON parser sees it);
- the entry names its source (the digest of its key: the mesh file's bytes, suffix,
  scale and the decomposition's settings), so an entry copied under another name does
  not check, and ends with a SHA-256 of everything before it, so a truncated or damaged
  one does not either;
- its pieces are what a decomposition gives: 1 to `MAX_PIECES`, each of 4 to
  `MAX_ENTRY_VERTICES` finite vertices spanning a volume;
- the digests are no secret, so an entry may still be forged; `fits` bounds what a
  forged one can do: its pieces must lie within the source mesh's own bounding box
  (scaled), give or take `TOLERANCE` of the box's diagonal (CoACD's hulls reach up to
  0.6 % of it past the box: a three-box arch), so a forged entry cannot turn a 0.5 m
  rock into a 1 km one.
An entry that fails any of this is ignored as if absent: the mesh is decomposed again
(within the mesh budgets) and the entry replaced; it never refuses a good mesh.

Layout (little-endian): `MAGIC` (8 bytes) | the key's digest (32) | the number of pieces
(uint32) | each piece's number of vertices (uint32 each) | the vertices (float64 x, y, z)
| SHA-256 of all the bytes before (32).
"""

from __future__ import annotations

import pathlib
import struct
from collections.abc import Sequence

import numpy as np

from ecs_tentacles.terrain.mesh_worker import MAX_PIECE_VERTICES, MAX_PIECES, has_volume
from ecs_tentacles.untrusted.sealed_cache import DIGEST, SealedCache, key_bytes

MAGIC = b"ECSTPCS1"
SUFFIX = ".pieces"
MAX_ENTRY_VERTICES = 4 * MAX_PIECE_VERTICES  # per piece: CoACD's decimation aims at 256
_HEAD = len(MAGIC) + DIGEST + 4  # magic, the key's digest, the number of pieces
MAX_ENTRY_BYTES = _HEAD + MAX_PIECES * (4 + 24 * MAX_ENTRY_VERTICES) + DIGEST
CACHE = SealedCache("meshes", MAGIC, SUFFIX, MAX_ENTRY_BYTES)
TOLERANCE = 0.05  # of the source box's diagonal: how far past the box a piece may reach

Pieces = tuple[np.ndarray, ...]


def cache_folder() -> pathlib.Path:
    """Where decomposed meshes are kept between runs."""
    return CACHE.folder()


def entry(key: str) -> pathlib.Path:
    """The file that keeps the pieces of `key` (a SHA-256 in hex)."""
    return CACHE.entry(key)


def sane(pieces: Sequence[np.ndarray]) -> bool:
    """Whether `pieces` are what a decomposition gives (the counts, finite vertices, each
    piece a volume)."""
    return 1 <= len(pieces) <= MAX_PIECES and all(
        p.ndim == 2
        and p.shape[1] == 3
        and 4 <= len(p) <= MAX_ENTRY_VERTICES
        and bool(np.isfinite(p).all())
        and has_volume(p)
        for p in pieces
    )


def encode(key: str, pieces: Sequence[np.ndarray]) -> bytes:
    """The entry's bytes for `pieces` under `key`."""
    return CACHE.seal(key, _payload(pieces))


def _payload(pieces: Sequence[np.ndarray]) -> bytes:
    """What an entry holds after the key: the count, each piece's size, the vertices."""
    sizes = struct.pack(f"<{len(pieces)}I", *(len(p) for p in pieces))
    vertices = b"".join(np.ascontiguousarray(p, dtype="<f8").tobytes() for p in pieces)
    return struct.pack("<I", len(pieces)) + sizes + vertices


def decode(key: str, data: bytes) -> Pieces | None:
    """The pieces in an entry's bytes, or None unless every check above holds (`fits`
    aside: it needs the source)."""
    body = CACHE.opened(key, data, 4)
    if body is None:
        return None
    (count,) = struct.unpack_from("<I", body, _HEAD - 4)
    if not 1 <= count <= MAX_PIECES or len(body) < _HEAD + 4 * count:
        return None
    sizes = np.frombuffer(body, "<u4", count, _HEAD).astype(np.int64)
    if (sizes < 4).any() or (sizes > MAX_ENTRY_VERTICES).any():
        return None
    start = _HEAD + 4 * count
    if len(body) != start + 24 * int(sizes.sum()):
        return None
    flat = np.frombuffer(body, "<f8", offset=start).reshape(-1, 3).astype(np.float64)
    pieces = tuple(np.split(flat, np.cumsum(sizes)[:-1]))
    return pieces if sane(pieces) else None


def read(key: str) -> Pieces | None:
    """The pieces kept under `key`, or None: absent, not a regular file, larger than
    `MAX_ENTRY_BYTES`, unreadable, or failing a check (`decode`)."""
    data = CACHE.load(key)
    return None if data is None else decode(key, data)


def fits(pieces: Pieces, box: np.ndarray) -> bool:
    """Whether every vertex of `pieces` lies in `box` ([lowest, highest] corner: the
    source mesh's, scaled), give or take `TOLERANCE` of its diagonal."""
    if box.shape != (2, 3) or not np.isfinite(box).all():
        return False
    low, high = box
    slack = TOLERANCE * float(np.linalg.norm(high - low))
    return all(bool(((p >= low - slack) & (p <= high + slack)).all()) for p in pieces)


def keep(key: str, pieces: Sequence[np.ndarray]) -> None:
    """Write `pieces` as the entry of `key`, atomically (`atomic_file`: a temporary file
    renamed into place); pieces that would not read back, or a cache that cannot be
    written, are skipped silently (the next run decomposes again)."""
    if key_bytes(key) and sane(pieces):
        CACHE.keep(key, _payload(pieces))
