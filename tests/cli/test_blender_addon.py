"""`ecs-tentacles blender-addon`: the zip is a Blender extension holding the add-on and
the project's two files it runs as they are; `--install` installs it into Blender's user
folder, enabled, keeping the user's preferences."""

from __future__ import annotations

import ast
import os
import sys
import zipfile
from pathlib import Path

import pytest

import ecs_tentacles
from ecs_tentacles.cli import main
from tests.blender_addon.conftest import BLENDER, install, needs_blender, run

PACKAGE = Path(ecs_tentacles.__file__).parent


def test_the_zip_holds_the_addon_and_the_skin_files_as_they_are(tmp_path: Path) -> None:
    out = tmp_path / "addon.zip"
    assert main(["blender-addon", "--out", str(out)]) == 0
    with zipfile.ZipFile(out) as archive:
        names = set(archive.namelist())
        addon = {
            p.name for p in (PACKAGE / "blender_addon").iterdir() if p.suffix in (".py", ".toml")
        }
        shared = {"skin_mesh.py", "skin_colours.py", "take_compact.py", "numeric_hamilton.py"}
        assert names == addon | shared
        assert (
            "blender_manifest.toml" in names
            and 'id = "ecs_tentacles_take"' in archive.read("blender_manifest.toml").decode()
        )
        assert archive.read("skin_mesh.py") == (PACKAGE / "skin" / "mesh.py").read_bytes()
        assert archive.read("skin_colours.py") == (PACKAGE / "skin" / "colours.py").read_bytes()
        assert archive.read("take_compact.py") == (PACKAGE / "take" / "compact.py").read_bytes()
        hamilton = (PACKAGE / "numeric" / "hamilton.py").read_bytes()
        assert archive.read("numeric_hamilton.py") == hamilton
        assert {i.date_time for i in archive.infolist()} == {(1980, 1, 1, 0, 0, 0)}
    again = tmp_path / "again.zip"
    assert main(["blender-addon", "--out", str(again)]) == 0
    assert again.read_bytes() == out.read_bytes()  # reproducible


def _imports(tree: ast.Module, anywhere: bool) -> list[str]:
    """The modules `tree` imports by absolute name: at its top level (with `anywhere`,
    inside functions too); never under `if TYPE_CHECKING:` (annotations only)."""
    typing_only = {
        id(n)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for n in ast.walk(node)
    }
    nodes = ast.walk(tree) if anywhere else iter(tree.body)
    found: list[str] = []
    for node in nodes:
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and not node.level:
            found.append(str(node.module))
    return found


@pytest.mark.parametrize("source", ["skin/mesh.py", "skin/colours.py", "blender_addon"])
def test_what_blender_runs_imports_only_numpy_and_the_standard_library(source: str) -> None:
    """Blender's Python has numpy and its own modules, not ecs_tentacles' dependencies:
    the add-on imports nothing else, and the two project files it carries nothing else
    when they load (`colours.look_in_world`, which Blender never calls, imports the
    engine's components)."""
    allowed = set(sys.stdlib_module_names) | {"numpy", "bpy", "bpy_extras", "mathutils"}
    addon = not source.endswith(".py")
    files = list((PACKAGE / source).glob("*.py")) if addon else [PACKAGE / source]
    for path in files:
        for module in _imports(ast.parse(path.read_text()), anywhere=addon):
            assert module.split(".")[0] in allowed, f"{path.name} imports {module}"


def test_blender_must_be_found(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fake = tmp_path / "blender"
    fake.write_text("#!/bin/sh\necho 'not blender'\n")
    fake.chmod(0o755)
    assert main(["blender-addon", "--install", "--blender", str(fake)]) == 2
    assert capsys.readouterr().err == (
        f"error: argument --blender: {fake} is neither Blender nor a Python\n"
    )


SET_PREFERENCE = """
bpy.context.preferences.view.ui_scale = 1.25
bpy.ops.wm.save_userpref()
print(json.dumps(True))
"""
READ_BACK = """
addons = [a.module for a in bpy.context.preferences.addons]
print(json.dumps({
    "addons": addons,
    "ui_scale": bpy.context.preferences.view.ui_scale,
    "operator": hasattr(bpy.types, "IMPORT_SCENE_OT_ecs_tentacles_take"),
}))
"""


@needs_blender
def test_install_enables_the_addon_in_a_fresh_user_folder_keeping_its_preferences(
    tmp_path: Path,
) -> None:
    folder = tmp_path / "user"
    env = {**os.environ, "BLENDER_USER_RESOURCES": str(folder)}
    run(env, SET_PREFERENCE)  # the user's own preference, saved before the install
    installed = install(folder)
    assert installed["BLENDER_USER_RESOURCES"] == str(folder) and BLENDER
    found = run(env, READ_BACK)
    assert "bl_ext.user_default.ecs_tentacles_take" in found["addons"]
    assert found["operator"] and found["ui_scale"] == 1.25
    assert (
        folder / "extensions" / "user_default" / "ecs_tentacles_take" / "skin_mesh.py"
    ).is_file()
