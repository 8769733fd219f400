"""The API reference, generated at build time (mkdocs-gen-files + mkdocstrings): one page
per module of the package, found by walking its folders as they are now, so a module that
moves or is added is documented where it lies, with no list to keep."""

from __future__ import annotations

from pathlib import Path

import mkdocs_gen_files

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "ecs_tentacles"
SKIP = {"__main__"}  # `python -m` entry points: no API

nav = mkdocs_gen_files.Nav()
for source in sorted(PACKAGE.rglob("*.py")):
    parts = source.relative_to(ROOT).with_suffix("").parts
    if parts[-1] in SKIP or any(part.startswith(".") for part in parts):
        continue
    if parts[-1] == "__init__":
        parts = parts[:-1]
        page = Path("reference", *parts, "index.md")
    else:
        page = Path("reference", *parts).with_suffix(".md")
    module = ".".join(parts)
    nav[parts] = page.relative_to("reference").as_posix()
    with mkdocs_gen_files.open(page, "w") as out:
        out.write(f"# `{module}`\n\n::: {module}\n")
    mkdocs_gen_files.set_edit_path(page, source.relative_to(ROOT))

with mkdocs_gen_files.open("reference/index.md", "w") as out:
    out.write(
        "# API reference\n\nEvery module of the package, from its docstrings, generated when"
        " the site is built. Start with `ecs_tentacles.world` (the World), `ecs_tentacles.plugin`"
        " and `ecs_tentacles.system` (what you subclass), `ecs_tentacles.registry` (what"
        " `build(app)` fills) and the [extension points](../extending/extension-points.md).\n"
    )
with mkdocs_gen_files.open("reference/SUMMARY.md", "w") as out:
    out.write("* [Overview](index.md)\n")
    out.writelines(nav.build_literate_nav())
