"""What an output file is, from its name: a take, USD or glTF (`output_kind`)."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["output_kind"]


def output_kind(path: str | os.PathLike[str]) -> str | None:
    """'take', 'usd' or 'gltf' from a file name's suffix, None if unsupported."""
    suffix = Path(path).suffix.lower()
    return {".npz": "take", ".usd": "usd", ".usda": "usd", ".usdc": "usd", ".glb": "gltf"}.get(
        suffix
    )
