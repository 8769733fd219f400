"""Core's code names no feature. Core is what the import contract "Core depends on no
feature" (pyproject's [tool.importlinter]) lists; the features are the packages its
"Features do not import each other" contract lists. In core's names and strings
(docstrings, comments and data files aside):

* no feature package's import path (`ecs_tentacles.locomotion`, ...), nor the examples'
  (`ecs_tentacles_examples`): not even a list of plugins (they are entry points);
* no feature word (`locomotion`, `fur`, `goals`, `guides`, `terrain`, `threat`,
  `director`, `herding`, `race`), but the columns sending a creature writes
  (`behaviour.destinations.DESTINATION_WRITES`), listed below; a new one fails here.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
import tomllib
from pathlib import Path

TOP = Path(__file__).resolve().parent.parent
ROOT = TOP / "ecs_tentacles"
CONTRACTS = tomllib.loads((TOP / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]


def _contract(prefix: str) -> dict[str, list[str]]:
    return next(c for c in CONTRACTS if c["name"].startswith(prefix))


FEATURE_PACKAGES = _contract("Features do not import each other")["modules"]
PATHS = re.compile("|".join(re.escape(m) + r"\b" for m in FEATURE_PACKAGES))
WORDS = re.compile(
    r"(?i)\b(locomotion|fur|goals?|guides?|terrain|threats?|director|herding|race)\b"
)


def _files(module: str) -> list[Path]:
    """The source files of `module` (the examples' package is in `systems/`)."""
    path = TOP.joinpath(*module.split("."))
    if module.startswith("ecs_tentacles_examples"):
        path = TOP / "systems" / path.relative_to(TOP)
    return (
        [path.with_suffix(".py")]
        if path.with_suffix(".py").is_file()
        else sorted(path.rglob("*.py"))
    )


CORE = [p for m in _contract("Core depends on no feature")["source_modules"] for p in _files(m)]

# (file, the name or string) still allowed, and why
ALLOWED = {
    # the columns the Destinations entry (the locomotion plugin's goals) writes: named
    # once in core so a behaviour's or game mode's systems can declare them from a public
    # module (issue 55), not from the examples package or another feature
    **{
        ("behaviour/destinations.py", s): "what sending a creature writes"
        for s in (
            '"goals"',
            '"locomotion.creatures.goal"',
            '"locomotion.creatures.has_goal"',
            '"locomotion.creatures.goal_radius"',
        )
    },
}


def _docstring_lines(tree: ast.AST) -> set[int]:
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            first = node.body[0] if node.body else None
            if ast.get_docstring(node, clean=False) is not None and isinstance(first, ast.Expr):
                lines.update(range(first.lineno, (first.end_lineno or first.lineno) + 1))
    return lines


def feature_names(pattern: re.Pattern[str] = WORDS) -> set[tuple[str, str]]:
    """(file relative to the package, token) of every feature name core's code says."""
    found = set()
    for path in CORE:
        source = path.read_text()
        skip = _docstring_lines(ast.parse(source))
        for token in tokenize.generate_tokens(io.StringIO(source).readline):
            if token.type not in (tokenize.NAME, tokenize.STRING) or token.start[0] in skip:
                continue
            if pattern.search(token.string):
                found.add((str(path.relative_to(ROOT)), token.string))
    return found


def test_core_is_what_the_contract_says_and_every_feature_is_a_package() -> None:
    assert len(CORE) > 80 and ROOT / "world.py" in CORE and ROOT / "scene" / "plugins.py" in CORE
    assert all(_files(m) for m in FEATURE_PACKAGES), FEATURE_PACKAGES


def test_core_names_no_feature_package_not_even_a_plugin_list() -> None:
    found = feature_names(PATHS)
    assert not found, f"core names a feature package: {sorted(found)}"


def test_core_code_names_no_feature_but_what_is_listed() -> None:
    unexpected = feature_names() - set(ALLOWED)
    assert not unexpected, f"core names a feature: {sorted(unexpected)}"


def test_the_list_has_nothing_core_no_longer_says() -> None:
    stale = set(ALLOWED) - feature_names()
    assert not stale, f"remove from ALLOWED: {sorted(stale)}"
