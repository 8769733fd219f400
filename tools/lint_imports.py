"""Check the import contracts (pyproject's [tool.importlinter]) over the package as it is
installed: `systems/` inside `ecs_tentacles` as `ecs_tentacles.systems`.

    python tools/lint_imports.py            # every contract; exit 1 if one is broken
    python tools/lint_imports.py --verbose  # and the chains it searched

The code imports the systems as `ecs_tentacles.systems...`, but `systems/` is a folder at
the top of the repository that the install maps into the package. import-linter reads
packages from disk, so run on the repository it saw the folder as `systems` and every
`ecs_tentacles.systems` import as an import of nothing: a contract forbidding one came
back kept. Here it reads a tree of links, `ecs_tentacles/*` and `ecs_tentacles/systems`
-> `systems/`, from a Python started without the site's path hooks and in that tree
(the editable install, and import-linter's own putting of its working directory first
on the path, would find the repository's `ecs_tentacles`), so every import is seen.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

RUN = """
import sys
sys.path[:0] = [{tree!r}]
sys.path.append({site!r})
from importlinter.cli import lint_imports_command
sys.argv = ["lint-imports", {config!r}, "--no-cache", *{extra!r}]
sys.exit(lint_imports_command())
"""


def link_tree(into: Path, root: Path = ROOT) -> Path:
    """`into/ecs_tentacles`: a link to each entry of the package and `systems` -> the
    repository's systems folder (copies where links cannot be made). Returns `into`."""
    package = into / "ecs_tentacles"
    package.mkdir()
    entries = [p for p in (root / "ecs_tentacles").iterdir() if p.name != "systems"]
    for source, name in [(p, p.name) for p in entries] + [(root / "systems", "systems")]:
        target = package / name
        try:
            target.symlink_to(source, target_is_directory=source.is_dir())
        except OSError:  # no symlinks (some Windows accounts): a copy reads the same
            if source.is_dir():
                shutil.copytree(source, target)
            else:
                shutil.copy2(source, target)
    return into


def lint(root: Path = ROOT, extra: tuple[str, ...] = ()) -> subprocess.CompletedProcess[str]:
    """Run import-linter with `root`'s pyproject.toml over `root`'s package; its output."""
    with tempfile.TemporaryDirectory(prefix="lint-imports-") as temp:
        tree = link_tree(Path(temp), root)
        site = sysconfig.get_paths()["purelib"]
        config = str(root / "pyproject.toml")
        code = RUN.format(tree=str(tree), site=site, config=config, extra=extra)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        return subprocess.run(
            [sys.executable, "-S", "-c", code],
            cwd=tree,  # import-linter puts its working directory first on the path
            env=env,
            capture_output=True,
            text=True,
            check=False,
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--verbose", action="store_true", help="the chains searched")
    args = parser.parse_args(argv)
    result = lint(extra=("--verbose",) if args.verbose else ())
    sys.stdout.write(result.stdout)
    sys.stderr.write(result.stderr)
    return result.returncode


if __name__ == "__main__":
    raise SystemExit(main())
