"""The Python subprocesses this package starts, isolated from the working folder.

`python -m module` puts the working folder first on the import path, so a `json.py`
or `numpy.py` lying where the user runs a command would run inside the child. Every
Python child is therefore started with `-P` (Python 3.11+: no unsafe path entry is
prepended; `PYTHONPATH`, which the user sets, still applies):

    subprocess.Popen(python_module("ecs_tentacles.terrain.mesh_worker", "1024"), ...)
"""

from __future__ import annotations

import sys


def python_module(module: str, *arguments: str) -> list[str]:
    """The command line running `module` in this interpreter, the working folder off
    the import path."""
    return [sys.executable, "-P", "-m", module, *arguments]
