"""Optional numba kernels: a module imported on first use, or None (numpy does the work).

    KERNELS = OptionalKernels("ecs_tentacles.clips.kernels", "ECS_TENTACLES_REPLAY")
    fast = KERNELS.get()         # the module, or None: numpy does the work

numba is optional (the ``dev`` extra installs it). The environment variable, when
given, picks the backend: "auto" (the default: the kernels when numba imports) or
"numpy" (always the whole-array numpy path: to compare, or to skip the compile);
`backend` can be set the same way from Python.
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType


class OptionalKernels:
    """A kernels module looked for once, on first use."""

    def __init__(self, module: str, variable: str | None = None):
        self.module = module
        self.backend = os.environ.get(variable, "auto") if variable else "auto"
        self._found: ModuleType | bool | None = False  # False: not looked for yet

    def get(self) -> ModuleType | None:
        """The kernels module, or None: numpy does the work."""
        if self.backend == "numpy":
            return None
        if self._found is False:
            try:
                self._found = importlib.import_module(self.module)
            except ImportError:  # numba is not installed
                self._found = None
        return self._found if isinstance(self._found, ModuleType) else None
