"""The README's picture sequences: four moments as a 2 x 2 sheet and a run as a GIF.

Used by `herding_screenshots.py` and `director_screenshots.py`; both files are written
through `output.atomic` (a failed run leaves the old pictures).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ecs_tentacles.output.atomic import atomic_output

if TYPE_CHECKING:
    from PIL import Image


def save_sequence(
    out_dir: Path,
    name: str,
    moments: list[Image.Image],
    frames: list[Image.Image],
    gif_width: int,
    frame_ms: int,
) -> tuple[Path, Path]:
    """`<name>_sequence.png` (the four `moments`, left to right, top to bottom) and
    `<name>.gif` (`frames`, `gif_width` px wide, `frame_ms` each, looping) in `out_dir`."""
    from PIL import Image

    if len(moments) != 4:
        raise ValueError(f"moments: a sheet holds 4 pictures, got {len(moments)}")
    w, h = moments[0].size
    sheet = Image.new("RGB", (2 * w, 2 * h))
    for i, picture in enumerate(moments):
        sheet.paste(picture, ((i % 2) * w, (i // 2) * h))
    png, gif = out_dir / f"{name}_sequence.png", out_dir / f"{name}.gif"
    with atomic_output(png) as temporary:
        sheet.save(temporary, format="PNG", optimize=True)
    small = [f.resize((gif_width, gif_width * h // w)).quantize(64) for f in frames]
    with atomic_output(gif) as temporary:
        small[0].save(
            temporary, format="GIF", save_all=True, append_images=small[1:], duration=frame_ms,
            loop=0,
        )  # fmt: skip
    return png, gif
