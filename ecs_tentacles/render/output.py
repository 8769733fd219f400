"""Screenshots (PNG) and videos (MP4 through ffmpeg), written by the one atomic writer.

Both go through `ecs_tentacles.output.atomic`: an exclusive temporary file beside the
target, renamed into place when complete. The video's ffmpeg (imageio-ffmpeg's
binary) writes to that temporary file; it is killed when the recording is aborted
(an error, Ctrl-C, SIGTERM) and, on Linux, when this process dies (SIGKILL).
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
from PIL import Image

from ecs_tentacles.output.atomic import AtomicOutput, OutputError, atomic_file


def save_png(pixels: np.ndarray, path: str | os.PathLike[str]) -> Path:
    """Write an (h, w, 3) uint8 picture; the file appears complete or not at all."""
    target = Path(path)
    with atomic_file(target) as handle:
        Image.fromarray(pixels).save(handle, format="PNG")
    return target


def _die_with_parent() -> None:  # pragma: no cover - runs in the child before exec
    """Linux: ffmpeg gets SIGKILL when this process dies, so it stops writing."""
    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def ffmpeg_command(path: Path, width: int, height: int, fps: float) -> list[str]:
    """H.264 from raw RGB frames on stdin (imageio-ffmpeg's settings, quality 7)."""
    import imageio_ffmpeg

    rate = str(Fraction(fps).limit_denominator())
    return [
        imageio_ffmpeg.get_ffmpeg_exe(),
        "-y", "-v", "error", "-hide_banner",
        "-f", "rawvideo", "-vcodec", "rawvideo", "-s", f"{width}x{height}",
        "-pix_fmt", "rgb24", "-r", rate, "-i", "-", "-an",
        "-vcodec", "libx264", "-pix_fmt", "yuv420p", "-crf", "15",
        "-f", "mp4", str(path),
    ]  # fmt: skip


class VideoWriter:
    """Frames in, an H.264 MP4 out; the file is renamed into place on `close`."""

    def __init__(self, path: str | os.PathLike[str], width: int, height: int, fps: float):
        if width % 2 or height % 2:
            raise ValueError(f"video size must be even, got {width}x{height}")
        self.path = Path(path)
        self.frames = 0
        self._output = AtomicOutput(self.path)
        descriptor = self._output.open()
        assert self._output.temporary is not None
        self.partial = self._output.temporary
        linux = sys.platform.startswith("linux")
        # On Linux ffmpeg opens /dev/fd/N: exactly the file we created, whatever
        # happens to its name meanwhile; elsewhere it opens the name.
        target = Path(f"/dev/fd/{descriptor}") if linux else self.partial
        try:
            self._process = subprocess.Popen(
                ffmpeg_command(target, width, height, fps),
                stdin=subprocess.PIPE,
                stdout=subprocess.DEVNULL,
                start_new_session=True,  # Ctrl-C reaches us, and we stop ffmpeg
                preexec_fn=_die_with_parent if linux else None,
                pass_fds=(descriptor,) if linux else (),
            )
        except BaseException:
            self._output.discard()
            raise
        finally:
            os.close(descriptor)
        self._same_file = linux

    def add(self, pixels: np.ndarray) -> None:
        """Append one (height, width, 3) uint8 frame."""
        assert self._process.stdin is not None
        try:
            self._process.stdin.write(np.ascontiguousarray(pixels).tobytes())
        except BrokenPipeError:
            self.abort()
            raise OutputError(f"{self.path}: ffmpeg stopped while recording") from None
        self.frames += 1

    def close(self) -> Path:
        """Finish the file and move it into place."""
        assert self._process.stdin is not None
        try:
            self._process.stdin.close()
            code = self._process.wait()
        except BaseException:
            self.abort()
            raise
        if code != 0:
            self._output.discard()
            raise OutputError(f"{self.path}: ffmpeg failed (exit {code}); nothing written")
        return self._output.commit(same_file=self._same_file)

    def abort(self) -> None:
        """Stop ffmpeg now and leave nothing behind."""
        try:
            if self._process.poll() is None:
                self._process.kill()
            self._process.wait()
            if self._process.stdin is not None:
                with contextlib.suppress(OSError):
                    self._process.stdin.close()
        finally:
            self._output.discard()
