"""`ecs-tentacles blender-addon`: the Blender add-on that opens takes, as a zip or installed.

    ecs-tentacles blender-addon --install                  # into Blender's user extensions
    ecs-tentacles blender-addon --install --blender /opt/blender/blender
    ecs-tentacles blender-addon --out ecs_tentacles_take.zip   # the extension, to install
    blender --command extension install-file -r user_default -e ecs_tentacles_take.zip

The zip is a Blender extension (Blender 4.4 or later: `blender_manifest.toml`): the files
of `ecs_tentacles.blender_addon` and the two project files it runs as they are
(`ecs_tentacles.blender_addon.shared`), written reproducibly (fixed dates) and atomically.
`--install` writes it to a temporary folder and installs it into the user's
`user_default` extensions repository, enabled, with the Blender given (default:
`blender` on the PATH), or with a Python that imports `bpy` (Blender as a module), which
then keeps the user's preferences (it reads them before it saves them). Blender's
`BLENDER_USER_RESOURCES` picks another user folder.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import zipfile
from importlib import resources
from pathlib import Path

from ecs_tentacles.cli.arguments import output_path
from ecs_tentacles.output.atomic import OutputError, atomic_file

PACKAGE = "ecs_tentacles.blender_addon"
ID = "ecs_tentacles_take"  # the manifest's id: Blender names the module bl_ext.<repo>.<id>
REPOSITORY = "user_default"
# the project's own files the add-on runs as they are (ecs_tentacles.blender_addon.shared)
SHARED = {"skin_mesh.py": ("ecs_tentacles.skin", "mesh.py"),
          "skin_colours.py": ("ecs_tentacles.skin", "colours.py"),
          "take_compact.py": ("ecs_tentacles.take", "compact.py"),
          "numeric_hamilton.py": ("ecs_tentacles.numeric", "hamilton.py")}  # fmt: skip
_EPOCH = (1980, 1, 1, 0, 0, 0)
INSTALL = """
import sys, bpy
zip_path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_userpref()  # bpy as a module starts on factory settings: keep the user's
bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo={repo!r}, enable_on_install=True
)
bpy.ops.wm.save_userpref()
enabled = {{a.module for a in bpy.context.preferences.addons}}
print("enabled" if "bl_ext.{repo}.{id}" in enabled else "not enabled")
"""
TIMEOUT = 300  # seconds an install may take (Blender starts in a few)


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "blender-addon",
        help="write or install the Blender add-on that imports takes (crowds sharing clips)",
        description="Write the Blender add-on (an extension zip for Blender 4.4+) that opens"
        " takes as armatures and skinned meshes, sharing data per body plan and actions per"
        " gait clip; or install it into Blender's user extensions, enabled.",
    )
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--out", type=output_path(".zip"), metavar="ZIP", help="write the zip")
    where.add_argument(
        "--install", action="store_true", help="install it into Blender's user extensions"
    )
    parser.add_argument(
        "--blender",
        metavar="PATH",
        help="with --install: Blender's executable, or a Python with bpy (default: blender)",
    )
    parser.set_defaults(handler=handle)


def write_zip(target: Path) -> list[str]:
    """Write the add-on's zip to `target` atomically; returns the names it holds."""
    files: list[tuple[str, bytes]] = []
    for entry in sorted(resources.files(PACKAGE).iterdir(), key=lambda e: e.name):
        if entry.is_file() and entry.name.endswith((".py", ".toml")):
            files.append((entry.name, entry.read_bytes()))
    for name, (package, source) in SHARED.items():
        files.append((name, resources.files(package).joinpath(source).read_bytes()))
    with atomic_file(target) as handle, zipfile.ZipFile(handle, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in files:
            info = zipfile.ZipInfo(name, date_time=_EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3
            info.external_attr = 0o644 << 16
            zf.writestr(info, data)
    return [name for name, _ in files]


def blender_kind(program: str) -> str:
    """ "blender" or "python" (a Python with bpy), from what `program --version` says;
    raises ValueError (one line) for neither."""
    try:
        done = subprocess.run(
            [program, "--version"], capture_output=True, text=True, timeout=60, check=False
        )
    except OSError as error:
        raise ValueError(f"argument --blender: cannot run {program}: {error.strerror}") from None
    except subprocess.TimeoutExpired:
        raise ValueError(f"argument --blender: {program} --version did not answer") from None
    said = (done.stdout + done.stderr).strip()
    if said.startswith("Blender"):
        return "blender"
    if said.startswith("Python"):
        return "python"
    raise ValueError(f"argument --blender: {program} is neither Blender nor a Python")


def install(program: str, zip_path: Path) -> str:
    """Install and enable the zip with `program` (Blender or a Python with bpy); returns
    the line to print. Raises ValueError (bad program) or OutputError (it failed)."""
    if blender_kind(program) == "blender":
        # Blender's own command (it runs in the background and saves the preferences)
        command = [program, "--command", "extension", "install-file", "-r", REPOSITORY,
                   "-e", str(zip_path)]  # fmt: skip
    else:
        code = INSTALL.format(repo=REPOSITORY, id=ID)
        command = [program, "-c", code, "--", str(zip_path)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        raise OutputError(f"{program}: the install took over {TIMEOUT} s; stopped") from None
    lines = (done.stdout + done.stderr).strip().splitlines()
    if done.returncode != 0 or "not enabled" in lines:
        last = lines[-1] if lines else f"exit status {done.returncode}"
        raise OutputError(f"{program}: the install failed: {last}")
    return f"blender-addon: installed {ID} into {REPOSITORY} with {program}, enabled"


def handle(args: argparse.Namespace) -> int:
    if args.blender is not None and not args.install:
        print("error: argument --blender: only with --install", file=sys.stderr)
        return 2
    if args.out is not None:
        names = write_zip(args.out)
        print(f"blender-addon: {args.out}: {ID} ({len(names)} files)")
        return 0
    program = args.blender or shutil.which("blender")
    if program is None:
        print("error: argument --blender: no blender on the PATH; give --blender PATH",
              file=sys.stderr)  # fmt: skip
        return 2
    with tempfile.TemporaryDirectory(prefix="ecs-tentacles-addon-") as folder:
        zip_path = Path(folder) / f"{ID}.zip"
        write_zip(zip_path)
        try:
            line = install(program, zip_path)
        except ValueError as error:
            print(f"error: {error}", file=sys.stderr)
            return 2
    print(line)
    return 0
