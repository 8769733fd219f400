"""An mkdocs hook for what a page's source marks for the build:

- `<!-- not run: why -->` on the line before a code block: the docs tests do not run that
  block (tests/docs/test_examples.py reads the marker); the built page shows why;
- `<!-- parsed, not run: why -->`: the docs tests check the block's commands without
  running them (tests/docs/parsed.py); the built page says so, and why;
- `<!-- slow: why -->`: the default tests check the block as a parsed one, and `pytest -m
  slow tests/docs` runs it as written (tests/docs/slow.py); the built page says so, and why;
- `<!-- where -->` in a table row whose first cell is a class name in backticks: the
  module that defines the class, found in the package's source when the site is built
  and linked to its API page (the extension-points index), so no module path is written
  by hand where modules move.
"""

from __future__ import annotations

import ast
import functools
import logging
import re
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
NOT_RUN = re.compile(r"^<!-- not run: (.+?) -->$", flags=re.M)
PARSED = re.compile(r"^<!-- parsed, not run: (.+?) -->$", flags=re.M)
SLOW = re.compile(r"^<!-- slow: (.+?) -->$", flags=re.M)
CHECKED = "how-the-code-blocks-are-checked"  # the heading of docs/about.md that says how
WHERE = re.compile(r"^(\| `(\w+)` \|[^\n]*?)<!-- where -->", flags=re.M)
log = logging.getLogger("mkdocs.hooks.markers")


KINDS = ("Registry", "Event")  # what an indexed class is, where a name is used twice


@functools.cache
def classes() -> dict[str, list[tuple[str, str]]]:
    """Every class defined at the top of a module of the package: name -> (module, bases)."""
    found: dict[str, list[tuple[str, str]]] = {}
    for source in sorted((ROOT / "ecs_tentacles").rglob("*.py")):
        parts = source.relative_to(ROOT).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        for node in ast.parse(source.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef):
                bases = " ".join(ast.unparse(base) for base in node.bases)
                found.setdefault(node.name, []).append((module, bases))
    return found


def where(name: str, depth: int) -> str:
    """A link to the API page of the one module defining class `name`."""
    candidates = classes().get(name, [])
    modules = [module for module, _ in candidates]
    if len(modules) > 1:  # Lines: the registry, and a GL batch in the renderer
        modules = [module for module, bases in candidates if any(k in bases for k in KINDS)]
    if len(modules) != 1:
        log.warning("extension points: class %s is defined in %s", name, modules or "no module")
        return "?"
    module = modules[0]
    path = "/".join(module.split("."))
    page = f"{path}/index.md" if (ROOT / path / "__init__.py").is_file() else f"{path}.md"
    return f"[`{module}`]({'../' * depth}reference/{page})"


def on_page_markdown(markdown: str, page: Any, **_: Any) -> str:
    """Each marker replaced as the module docstring says."""
    depth = page.file.src_uri.count("/")
    markdown = NOT_RUN.sub(lambda m: f"*Not run by the docs tests: {m.group(1)}.*\n", markdown)
    how = f"{'../' * depth}about.md#{CHECKED}"
    markdown = PARSED.sub(
        lambda m: f"*Checked, not run, by the docs tests ([how]({how})): {m.group(1)}.*\n",
        markdown,
    )
    markdown = SLOW.sub(
        lambda m: f"*Run by the slow docs tests ([how]({how})): {m.group(1)}.*\n", markdown
    )
    return WHERE.sub(lambda m: m.group(1) + where(m.group(2), depth), markdown)
