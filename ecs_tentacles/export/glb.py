"""The GLB container: a binary chunk streamed to disk, then the file written whole.

    def document(buffer: GlbBuffer) -> dict:       # accessors' bytes go to disk as added
        ...                                        # the JSON is built beside them
    stream_glb(path, document)                     # the file written whole, atomically

A GLB is a 12-byte header, a JSON chunk, then the binary chunk; the JSON (byte offsets,
accessor bounds) is only known once every array is in the binary chunk, so the arrays
are spooled to an unnamed temporary file beside the target as they are made (Linux
`O_TMPFILE`: nothing is left behind whatever stops the run) and copied after the JSON.
Memory holds the JSON and one array at a time, never the file; the disk holds the file
twice while it is assembled.

Every length in a GLB is a uint32 (the header's total, each chunk's), so a file holds
at most `GLB_MAX_BYTES`; `write_glb_file` refuses more (`GlbTooLarge`) before writing a
byte, and `export.glb_size` counts it from a take's or scene's shapes before any work.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import struct
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, TYPE_CHECKING, BinaryIO

import numpy as np

from ecs_tentacles.output.atomic import atomic_file

if TYPE_CHECKING:
    from ecs_tentacles.export.gltf_types import Accessor, AccessorType, BufferView, Document

GLB_MAX_BYTES = 2**32 - 1  # the header's total length is a uint32
FLOAT, USHORT, UINT = 5126, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
_GLB_MAGIC, _JSON_CHUNK, _BIN_CHUNK = 0x46546C67, 0x4E4F534A, 0x004E4942
COPY_BYTES = 1024**2  # the spool is copied into the file in pieces of this size


class GlbTooLarge(ValueError):
    """A glb would pass glTF's 4 GiB; the message is one line naming the file."""


class GlbBuffer:
    """The binary chunk under construction: one buffer view and accessor per array, its
    bytes written to `sink` as they come (a spool file, or memory by default)."""

    def __init__(self, sink: IO[bytes] | None = None) -> None:
        self.sink: IO[bytes] = io.BytesIO() if sink is None else sink
        self.length = 0  # bytes written so far, each view padded to 4
        self.views: list[BufferView] = []
        self.accessors: list[Accessor] = []

    def view(self, raw: bytes | memoryview, target: int | None = None) -> int:
        """Append `raw` as a buffer view (zero-padded to 4 bytes); its index."""
        size = len(memoryview(raw).cast("B"))
        view: BufferView = {"buffer": 0, "byteOffset": self.length, "byteLength": size}
        if target is not None:
            view["target"] = target
        self.sink.write(raw)
        pad = -size % 4
        if pad:
            self.sink.write(b"\0" * pad)
        self.length += size + pad
        self.views.append(view)
        return len(self.views) - 1

    def add(self, array: np.ndarray, kind: AccessorType, target: int | None = None) -> int:
        """Append `array` (float32, uint16 or uint32), return its accessor index; float
        VEC3 and SCALAR accessors carry their bounds (`min`, `max`)."""
        data = np.ascontiguousarray(array)
        accessor: Accessor = {
            "bufferView": self.view(data.tobytes() if data.size else b"", target),
            "componentType": {np.dtype(np.float32): FLOAT, np.dtype(np.uint32): UINT}.get(
                data.dtype, USHORT
            ),
            "count": int(data.shape[0]),
            "type": kind,
        }
        if kind in ("VEC3", "SCALAR") and data.dtype == np.float32:
            flat = data.reshape(data.shape[0], -1)
            accessor["min"] = flat.min(axis=0).tolist()
            accessor["max"] = flat.max(axis=0).tolist()
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def fields(self) -> Document:
        """The document's `buffers`, `bufferViews` and `accessors`."""
        return {"buffers": [{"byteLength": self.length}], "bufferViews": self.views,
                "accessors": self.accessors}  # fmt: skip

    def value(self) -> bytes:
        """The binary chunk held in memory (a buffer made without a sink)."""
        assert isinstance(self.sink, io.BytesIO), "a spooled buffer is on disk"
        return self.sink.getvalue()


def stream_glb(path: str | os.PathLike[str], document: Callable[[GlbBuffer], Document]) -> int:
    """Write a GLB to `path` atomically: `document(buffer)` adds its arrays to a buffer
    spooled beside `path` and returns the JSON; then the file is written. Its size.
    Any error (a full disk: one line naming `path`) or stop leaves nothing behind."""
    with atomic_file(path) as handle, spool_beside(path) as spool:
        buffer = GlbBuffer(spool)
        return write_glb_file(handle, document(buffer), buffer, path)


@contextlib.contextmanager
def spool_beside(path: str | os.PathLike[str]) -> Iterator[BinaryIO]:
    """An unnamed temporary file in `path`'s folder (same disk as the output; gone when
    closed or when the process dies)."""
    folder = Path(path).resolve().parent
    with tempfile.TemporaryFile(dir=folder) as spool:
        yield spool


def _json_chunk(document: Document) -> bytes:
    text = json.dumps(document, separators=(",", ":"), sort_keys=True, allow_nan=False).encode()
    return text + b" " * (-len(text) % 4)


def _header(text: bytes, binary_length: int) -> bytes:
    total = 12 + 8 + len(text) + 8 + binary_length
    return b"".join(
        [
            struct.pack("<III", _GLB_MAGIC, 2, total),
            struct.pack("<II", len(text), _JSON_CHUNK),
            text,
            struct.pack("<II", binary_length, _BIN_CHUNK),
        ]
    )


def write_glb_file(
    handle: IO[bytes], document: Document, buffer: GlbBuffer, path: object = "glb"
) -> int:
    """Write the GLB of `document` and `buffer`'s binary chunk to `handle`; its size.
    `GlbTooLarge` (nothing written) when it would pass `GLB_MAX_BYTES`."""
    text = _json_chunk(document)
    total = 12 + 8 + len(text) + 8 + buffer.length
    if total > GLB_MAX_BYTES:
        raise GlbTooLarge(
            f"{path}: the glb would be {total:,} bytes; a glb holds at most"
            f" {GLB_MAX_BYTES:,} (4 GiB: its lengths are 32-bit): export to .usdc"
        )
    handle.write(_header(text, buffer.length))
    del text
    buffer.sink.flush()
    buffer.sink.seek(0)
    piece = memoryview(bytearray(COPY_BYTES))
    while count := buffer.sink.readinto(piece):  # type: ignore[attr-defined]
        handle.write(piece[:count])
    return total


def glb_bytes(document: Document, binary: bytes) -> bytes:
    """A GLB container in memory: 12-byte header, JSON chunk (space-padded), BIN chunk
    (zero-padded)."""
    text = _json_chunk(document)
    binary += b"\0" * (-len(binary) % 4)
    return _header(text, len(binary)) + binary


def read_glb(data: bytes) -> tuple[Document, bytes]:
    """Split a GLB into its JSON document and binary chunk (for tests and tools)."""
    magic, version, total = struct.unpack_from("<III", data, 0)
    if magic != _GLB_MAGIC or version != 2 or total != len(data):
        raise ValueError("not a glTF 2.0 binary file")
    json_length, _ = struct.unpack_from("<II", data, 12)
    document: Document = json.loads(data[20 : 20 + json_length])
    bin_length, _ = struct.unpack_from("<II", data, 20 + json_length)
    start = 28 + json_length
    return document, data[start : start + bin_length]


def accessor_array(document: Document, binary: bytes, index: int) -> np.ndarray:
    """Read accessor `index` of a document as a numpy array (float32 or uint16)."""
    accessor = document["accessors"][index]
    view = document["bufferViews"][accessor["bufferView"]]
    dtype = np.float32 if accessor["componentType"] == FLOAT else np.uint16
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[accessor["type"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    flat = np.frombuffer(binary, dtype=dtype, count=accessor["count"] * width, offset=start)
    return flat.reshape(accessor["count"], width) if width > 1 else flat
