"""Writing a take as its frames come: `TakeWriter` (version 2, `ecs_tentacles.take.chunks`).

    with TakeWriter("shot.npz", chunk_frames=64) as writer:
        writer.add_frames({"pos": ..., "quat": ..., ...})   # any number of frames, in order
        writer.finish(header, other_arrays)                  # the header last

The frames of the chunked arrays are buffered up to a chunk and stored (deflated) as each
chunk fills, so a bake's memory holds one chunk, not the shot. Deflating and writing run
on a thread of the writer's own (zlib lets go of the interpreter), one chunk behind the
simulation: a bake does not wait for its take to be compressed. The file is written to a
temporary name beside the target and renamed when `finish` returns and the block ends
(`ecs_tentacles.output.atomic`); leaving the block by an exception (Ctrl-C included)
removes it, so a stopped bake leaves neither a take nor chunks.
"""

from __future__ import annotations

import contextlib
import os
import queue
import threading
import zipfile
from collections.abc import Callable
from types import TracebackType

import numpy as np

from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.take import chunks, compact
from ecs_tentacles.take.header import VERSION


class TakeWriter:
    """A version 2 take file being written (see the module docstring)."""

    def __init__(
        self,
        path: str | os.PathLike[str],
        chunk_frames: int | None = None,
        progress: Callable[[int], object] | None = None,
        quantised: dict[str, float] | None = None,
    ) -> None:
        if chunk_frames is not None and chunk_frames < 1:
            raise ValueError(f"chunk_frames must be >= 1, got {chunk_frames}")
        self.path = path
        self.chunk_frames = chunk_frames
        self.progress = progress
        self.quantised = dict(quantised or {})  # array name -> step (`chunks.quantise`)
        self.frames = 0  # frames given so far
        self.stored = 0  # bytes stored so far (before compression)
        self._pending: dict[str, list[np.ndarray]] = {}
        self._pending_frames = 0
        self._chunk = 0
        self._stack = contextlib.ExitStack()
        self._archive: zipfile.ZipFile | None = None
        self._finished = False
        self._discarded = False
        self._queue: queue.Queue[tuple[str, list[np.ndarray], float | None] | None] = queue.Queue(
            maxsize=1
        )
        self._thread: threading.Thread | None = None
        self._failure: BaseException | None = None
        self._abort = False

    def __enter__(self) -> TakeWriter:
        handle = self._stack.enter_context(atomic_file(self.path))
        self._archive = zipfile.ZipFile(handle, "w", allowZip64=True)
        self._thread = threading.Thread(target=self._store, name="take writer", daemon=True)
        self._thread.start()
        return self

    def _store(self) -> None:
        """The writer's thread: each entry handed over (its frames' parts joined and, for
        a quantised array, put in steps here), deflated into the archive."""
        while (item := self._queue.get()) is not None:
            if self._abort or self._failure is not None:
                continue  # stopped: the entries left are dropped
            try:
                assert self._archive is not None
                name, parts, step = item
                joined = parts[0] if len(parts) == 1 else np.concatenate(parts)
                stored = joined if step is None else chunks.quantise(joined, step)
                chunks.add_entry(self._archive, name, chunks.npy_bytes(stored))
            except BaseException as error:  # handed to the main thread at its next entry
                self._failure = error

    def _join(self) -> None:
        """Wait for the thread to store what it was handed; raise what it failed with."""
        if self._thread is not None:
            self._queue.put(None)
            self._thread.join()
            self._thread = None
        if self._failure is not None:
            failure, self._failure = self._failure, None
            raise failure

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> bool | None:
        if error is not None or self._discarded or not self._finished:
            self._abort = True  # nothing more is stored
        with contextlib.suppress(BaseException):
            if error is not None:  # the thread's own failure matters no more
                self._join()
        if error is None and self._thread is not None:
            try:
                self._join()
            except BaseException as failure:  # e.g. the disk filled: no file
                error, kind, trace = failure, type(failure), failure.__traceback__
        if self._archive is not None:  # its central directory: the file is whole (or dropped)
            archive, self._archive = self._archive, None
            with contextlib.suppress(Exception):
                archive.close()
        if error is not None:
            return self._stack.__exit__(kind, error, trace)  # the temporary file removed
        if self._discarded or not self._finished:
            stop: Exception = (
                _Discarded() if self._discarded else RuntimeError(f"{self.path}: not finished")
            )
            self._stack.__exit__(type(stop), stop, None)
            if not self._discarded:
                raise stop
            return None
        return self._stack.__exit__(None, None, None)  # renamed into place

    def add_frames(self, arrays: dict[str, np.ndarray]) -> None:
        """Append frames (every array holds the same number, along its first axis)."""
        if self.chunk_frames is None:
            raise ValueError("set chunk_frames before the first frames")
        counts = {len(a) for a in arrays.values()}
        if len(counts) != 1:
            raise ValueError("every chunked array must hold the same frames")
        (count,) = counts
        taken = 0
        while taken < count:
            room = self.chunk_frames - self._pending_frames
            part = {k: a[taken : taken + room] for k, a in arrays.items()}
            for name, value in part.items():
                self._pending.setdefault(name, []).append(np.array(value))
            moved = len(next(iter(part.values())))
            self._pending_frames += moved
            taken += moved
            self.frames += moved
            if self._pending_frames == self.chunk_frames:
                self._store_chunk()

    def _store_chunk(self) -> None:
        if not self._pending_frames:
            return
        for name, parts in self._pending.items():
            widest = max(p.shape[1] for p in parts) if parts[0].ndim > 1 else None
            if widest is not None:  # a creature came within the chunk: later frames are wider
                parts = [_pad_to_later(p, parts, widest) for p in parts]
            entry = chunks.entry_name(name, self._chunk)
            self._entry(entry, parts, self.quantised.get(name))
        self._pending = {}
        self._pending_frames = 0
        self._chunk += 1

    def _entry(
        self, name: str, array: np.ndarray | list[np.ndarray], step: float | None = None
    ) -> None:
        """Store `array` (or the frames' parts of one, joined on the writer's thread and
        put in steps of `step` there) as entry `name`; the parts are the writer's own."""
        assert self._thread is not None, "TakeWriter is used in a with block"
        if self._failure is not None:
            self._join()  # raises it
        parts = array if isinstance(array, list) else [array]
        self._queue.put((name, parts, step))
        told = sum(part.nbytes for part in parts)
        self.stored += told
        if self.progress is not None:
            self.progress(told)

    def discard(self) -> None:
        """Keep nothing: the temporary file is removed when the block ends."""
        self._discarded = True

    def finish(self, header: dict[str, object], arrays: dict[str, np.ndarray]) -> None:
        """Store the last chunk, the arrays without chunks and the header (`frames` and
        `chunk_frames` set here); the file is renamed into place when the block ends."""
        self._store_chunk()
        if self.chunk_frames is None:
            raise ValueError("a take holds at least one frame")
        for name, array in arrays.items():
            self._entry(f"{name}.npy", array)
        header = {**header, "version": VERSION, "frames": self.frames,
                  "chunk_frames": self.chunk_frames}  # fmt: skip
        if self.quantised:
            header["quantised"] = dict(self.quantised)
        text = compact.header_text(header)
        self._entry("header.npy", np.frombuffer(text.encode(), dtype=np.uint8))
        self._join()  # every entry stored (or the failure raised here)
        self._finished = True


class _Discarded(Exception):
    """The writer's file is not kept (`TakeWriter.discard`)."""


def _pad_to_later(part: np.ndarray, parts: list[np.ndarray], widest: int) -> np.ndarray:
    """`part` widened to `widest` items, each missing one holding its value at the first
    later frame (of `parts`) that has it."""
    if part.shape[1] == widest:
        return part
    later = next(p for p in parts if p.shape[1] == widest)
    fill = later[0, part.shape[1] :]
    return chunks.pad_items(part, widest, fill)
