"""Optional numba kernels: a module imported on first use, or None (numpy does the work).

    _KERNELS = OptionalKernels("ecs_tentacles.lod.kernels")
    fast = _KERNELS.get()        # the module, or None when numba is not installed

numba is optional (the ``dev`` extra installs it); each user keeps its own switch to
force the whole-array numpy path (`ECS_TENTACLES_RIG=numpy`, `ECS_TENTACLES_REPLAY=numpy`).
"""

from __future__ import annotations

import importlib
from types import ModuleType


class OptionalKernels:
    """A kernels module looked for once, on first use."""

    def __init__(self, module: str):
        self.module = module
        self._found: ModuleType | bool | None = False  # False: not looked for yet

    def get(self) -> ModuleType | None:
        """The kernels module, or None: numpy does the work."""
        if self._found is False:
            try:
                self._found = importlib.import_module(self.module)
            except ImportError:  # numba is not installed
                self._found = None
        return self._found if isinstance(self._found, ModuleType) else None
