"""usd-core's modules for the USD writers, or one line saying how to install them.

    pxr = usd_modules()        # pxr.Gf, pxr.Sdf, pxr.Usd, pxr.UsdGeom, pxr.Vt loaded

Imports usd-core only when called: the package works without the `usd` extra.
"""

from __future__ import annotations

from typing import Any


class UsdUnavailable(RuntimeError):
    """usd-core is not installed."""


def usd_modules() -> Any:
    """The `pxr` package with the modules every USD writer uses imported."""
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
    return pxr
