"""A USD stage written to its file while it fills, so a long take never sits in memory.

    with atomic_output("crowd.usdc") as temporary:
        layer = StreamedLayer(temporary)          # an empty stage whose root layer is the file
        ...define prims on layer.stage...
        for first, chunk in source.chunks():
            ...time samples: layer.sample(path, frame, value), in `layer.batch()`...
            layer.flush()                         # appends what was added, past FLUSH_BYTES
        layer.finish()

USD's binary format (crate: `.usdc`, and `.usd` unless the environment picks text)
saves a layer it wrote before by appending what changed: the values already in the
file stay there and are read back only when asked (usd-core 26.11: saving a 200-prim
layer after every 100 frames kept the process at its size while the file grew by the
new samples alone). What stays in memory is USD's index of the samples: about 70
bytes a time sample, whatever its value holds. Each save also rewrites, for every
attribute given samples since, the list of where its samples are (8 bytes a sample so
far; the old list stays in the file as dead bytes), so saving after every chunk would
grow the file with the square of the take. `flush` therefore saves once the new
samples pass `FLUSH_BYTES` and four times what that rewrite costs (`REWRITE_SHARE`):
the dead bytes stay under a quarter of the file, and what waits in memory for the
next save grows with the take's samples only as much as the index does.
A text layer (`.usda`) cannot append: it is written once, at the end.
`StreamedLayer(None)` is a stage in memory (tests, `build_*_stage`).

Sdf-level samples in an `Sdf.ChangeBlock` (`batch`, `sample`) were the fastest way in
(usd-core 26.11, 20,000 samples of 81 quaternions): 4.0-4.9 us a sample, against 9.6
for `Sdf.Layer.SetTimeSample` alone and 11.7 for `Usd.Attribute.Set`.

Writes the file at the path it is given (the caller's temporary file); reads nothing.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from types import ModuleType
from typing import TYPE_CHECKING

from ecs_tentacles.export.usd_pxr import usd_modules as _pxr

if TYPE_CHECKING:
    from pxr import Sdf

FLUSH_BYTES = 64 * 1024**2  # samples held in memory before the file is saved, at least
REWRITE_SHARE = 4  # ... and this many times the bytes a save rewrites (8 a sample so far)


class StreamedLayer:
    """A stage on a root layer that is saved to `path` as it grows (crate) or at the end."""

    def __init__(self, path: str | os.PathLike[str] | None) -> None:
        pxr = _pxr()
        self.Sdf = pxr.Sdf
        if path is None:
            self.stage = pxr.Usd.Stage.CreateInMemory()
        else:
            # the temporary file exists (created empty, exclusively): the layer writes it
            self.stage = pxr.Usd.Stage.Open(pxr.Sdf.Layer.CreateNew(os.fspath(path)))
        self.layer = self.stage.GetRootLayer()
        self.appends = path is not None and _crate(pxr, self.layer)
        self.pending = 0  # bytes of samples added since the last save
        self.samples = 0  # time samples authored so far
        self.saves = 0

    @contextlib.contextmanager
    def batch(self) -> Iterator[None]:
        """Edits inside are announced to the stage once, at the end (`Sdf.ChangeBlock`):
        2.4x faster per time sample than `Usd.Attribute.Set` one at a time."""
        with self.Sdf.ChangeBlock():
            yield

    def sample(self, path: object, time: float, value: object, nbytes: int = 16) -> None:
        """Author `value` at `time` on the attribute at `path` (an `Sdf.Path`); `nbytes`:
        about what it holds, counted towards the next save."""
        self.layer.SetTimeSample(path, time, value)
        self.pending += nbytes
        self.samples += 1

    def flush(self, force: bool = False) -> None:
        """Save the layer when it appends and enough was added since the last save
        (`FLUSH_BYTES`, `REWRITE_SHARE` times the rewrite; with `force`, anything)."""
        due = max(FLUSH_BYTES, REWRITE_SHARE * 8 * self.samples)
        if self.appends and (self.pending >= due or (force and self.pending)):
            self.save()

    def save(self) -> None:
        """Write the layer to its file now."""
        if not self.layer.Save():
            raise OSError(f"{self.layer.realPath}: USD could not write the file")
        self.pending = 0
        self.saves += 1

    def finish(self) -> None:
        """The last save: the file holds the whole stage."""
        self.save()


def _crate(pxr: ModuleType, layer: Sdf.Layer) -> bool:
    """Whether `layer` is written in the binary crate format (`.usdc`; `.usd` unless
    `USD_DEFAULT_FILE_FORMAT` asks for text)."""
    format_id = layer.GetFileFormat().formatId
    if format_id == "usd":
        format_id = pxr.Sdf.UsdFileFormat.GetUnderlyingFormatForLayer(layer)
    return bool(format_id == "usdc")
