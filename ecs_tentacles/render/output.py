"""Screenshots (PNG) and videos (MP4 through imageio-ffmpeg), written atomically."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image


def _temporary(path: Path) -> Path:
    return path.with_name(f".{path.stem}.partial{path.suffix}")


def save_png(pixels: np.ndarray, path: str | os.PathLike[str]) -> Path:
    """Write an (h, w, 3) uint8 picture; the file appears complete or not at all."""
    target = Path(path)
    partial = _temporary(target)
    try:
        Image.fromarray(pixels).save(partial, format="PNG")
        os.replace(partial, target)
    finally:
        partial.unlink(missing_ok=True)
    return target


class VideoWriter:
    """Frames in, an H.264 MP4 out; the file is renamed into place on `close`."""

    def __init__(self, path: str | os.PathLike[str], width: int, height: int, fps: float):
        import imageio_ffmpeg

        self.path = Path(path)
        self.partial = _temporary(self.path)
        self.frames = 0
        self._writer: Any = imageio_ffmpeg.write_frames(
            str(self.partial),
            (width, height),
            fps=fps,
            codec="libx264",
            quality=7,
            macro_block_size=8,
            ffmpeg_log_level="error",
        )
        self._writer.send(None)

    def add(self, pixels: np.ndarray) -> None:
        self._writer.send(np.ascontiguousarray(pixels).tobytes())
        self.frames += 1

    def close(self) -> Path:
        """Finish the file and move it into place."""
        self._writer.close()
        os.replace(self.partial, self.path)
        return self.path

    def abort(self) -> None:
        """Stop and leave nothing behind."""
        try:
            self._writer.close()
        finally:
            self.partial.unlink(missing_ok=True)
