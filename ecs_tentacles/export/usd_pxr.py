"""usd-core's modules for the USD writers, or one line saying how to install them.

    pxr = usd_modules()        # pxr.Gf, pxr.Sdf, pxr.Usd, pxr.UsdGeom, pxr.Vt loaded

Imports usd-core only when called: the package works without the `usd` extra.

Crate files (`.usdc`) are read with `pread`, not mapped (`USDC_USE_PREAD`, unless the
environment says otherwise): a mapped file's pages count in the process's resident
memory as they are read, so checking a crowd's 1 GB file (`--validate`) held 784 MB,
with reads 189 MB (usd-core 26.11; 5 s and 8 s).
"""

from __future__ import annotations

import os
from types import ModuleType


class UsdUnavailable(RuntimeError):
    """usd-core is not installed."""


def usd_modules() -> ModuleType:
    """The `pxr` package with the modules every USD writer uses imported."""
    os.environ.setdefault("USDC_USE_PREAD", "1")  # read before pxr opens a crate file
    try:
        import pxr.Gf
        import pxr.Sdf
        import pxr.Usd
        import pxr.UsdGeom
        import pxr.Vt
    except ImportError:
        raise UsdUnavailable(
            "writing USD needs usd-core: pip install 'ecs-tentacles[usd]'"
        ) from None
    package: ModuleType = pxr  # (untyped: usd-core ships no stubs)
    return package
