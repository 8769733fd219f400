"""The Python subprocesses this package starts, isolated from the working folder.

`python -m module` puts the working folder first on the import path, so a `json.py`
or `numpy.py` lying where the user runs a command would run inside the child. Every
Python child is therefore started with `-P` (Python 3.11+: no unsafe path entry is
prepended; `PYTHONPATH`, which the user sets, still applies):

    subprocess.Popen(python_module("ecs_tentacles.terrain.mesh_worker", "1024"), ...)

A dependency's children count too: `import mujoco` imports `glfw`, which, unless told
where its library is, tries every `libglfw.so` it can find, the working folder's first,
each in a `python -c` child that has the working folder on its import path (a
`ctypes.py` there runs, and so does the library's own code). `no_library_search()`,
called when this package is imported, points it at the library it ships.
"""

from __future__ import annotations

import importlib.util
import os
import sys


def python_module(module: str, *arguments: str) -> list[str]:
    """The command line running `module` in this interpreter, the working folder off
    the import path."""
    return [sys.executable, "-P", "-m", module, *arguments]


def no_library_search() -> None:
    """Tell `glfw` (imported by `import mujoco`) which library to load, so it searches
    no folder and starts no child: the one its wheel ships (as it would pick it), else
    MuJoCo's OpenGL is switched off (this package draws with pyglet). A user's own
    `PYGLFW_LIBRARY` or `MUJOCO_GL` is kept. Child processes inherit the setting."""
    if os.environ.get("PYGLFW_LIBRARY") or "glfw" in sys.modules:
        return
    library = _shipped_glfw()
    if library is not None:
        os.environ["PYGLFW_LIBRARY"] = library
    else:
        os.environ.setdefault("MUJOCO_GL", "disable")


def _shipped_glfw() -> str | None:
    """The GLFW library inside the installed `glfw` package (X11 unless the session is
    Wayland, as glfw itself chooses), found without importing it. (os.path, not pathlib:
    `python -m ecs_tentacles` imports this before its working folder is off the path.)"""
    try:
        spec = importlib.util.find_spec("glfw")
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    package = next(iter(spec.submodule_search_locations))
    variant = os.environ.get("PYGLFW_LIBRARY_VARIANT", "").lower()
    if variant not in ("x11", "wayland"):
        variant = "wayland" if os.environ.get("XDG_SESSION_TYPE") == "wayland" else "x11"
    for name in (os.path.join(variant, "libglfw.so"), "libglfw.so", "libglfw.3.dylib", "glfw3.dll"):
        candidate = os.path.join(package, name)
        if os.path.isfile(candidate):
            return candidate
    return None


def working_folder_off_path() -> None:
    """`python -m ecs_tentacles` put the working folder first on the import path: take
    it off before anything else is imported (`python -P` and the `ecs-tentacles`
    script never put it there)."""
    if sys.flags.safe_path or not sys.path:
        return
    first = sys.path[0]
    if os.path.abspath(first or os.curdir) == os.getcwd():
        del sys.path[0]
