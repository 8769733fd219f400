"""File > Import > ecs_tentacles take (.npz): the operator `import_scene.ecs_tentacles_take`.

Progress shows in Blender's status bar (`window_manager.progress_*`) and as a line on
stdout at every tenth of the work. A file that is not a sound take is reported as one
error line (a script calling the operator gets it as a RuntimeError) and nothing is
made.
"""

from __future__ import annotations

import time

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper

from .build import import_take
from .reader import TakeFileError

PREFIX = "ecs_tentacles take"


class Progress:
    """Reports an import's progress: the window manager's bar, and a line on stdout per
    tenth (with the seconds since the start)."""

    def __init__(self, context: bpy.types.Context) -> None:
        self.manager = context.window_manager
        self.manager.progress_begin(0, 100)
        self.start = time.monotonic()
        self.told = -1

    def __call__(self, fraction: float, text: str) -> None:
        self.manager.progress_update(int(100 * fraction))
        tenth = int(10 * fraction + 1e-9)
        if tenth > self.told:
            self.told = tenth
            seconds = time.monotonic() - self.start
            print(f"{PREFIX}: {100 * fraction:3.0f} % {text} ({seconds:.1f} s)", flush=True)

    def end(self) -> None:
        self.manager.progress_end()


# bpy has no type information outside Blender: mypy cannot see its classes
class ImportTake(bpy.types.Operator, ImportHelper):  # type: ignore[misc, unused-ignore]
    """Import an ecs_tentacles take (.npz): creatures as armatures with skinned meshes"""

    bl_idname = "import_scene.ecs_tentacles_take"
    bl_label = "Import ecs_tentacles take"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".npz"
    filter_glob: StringProperty(default="*.npz", options={"HIDDEN"})  # type: ignore[valid-type]

    def execute(self, context: bpy.types.Context) -> set[str]:
        progress = Progress(context)
        try:
            made = import_take(context, self.filepath, progress)
        except TakeFileError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            progress.end()
        self.report({"INFO"}, made)  # (Blender prints it too when in the background)
        return {"FINISHED"}


def menu(self: bpy.types.Menu, context: bpy.types.Context) -> None:
    self.layout.operator(ImportTake.bl_idname, text="ecs_tentacles take (.npz)")


def register() -> None:
    bpy.utils.register_class(ImportTake)
    bpy.types.TOPBAR_MT_file_import.append(menu)


def unregister() -> None:
    bpy.types.TOPBAR_MT_file_import.remove(menu)
    bpy.utils.unregister_class(ImportTake)
