"""Core's code names no feature: no `locomotion`, `fur`, `goals`, `guides`, `terrain`,
`threat`, `director` or `herding` in the names and strings of the package top,
`creatures/`, `ground/`, `numeric/`, `output/`, `physics/`, `scene/` and `take/`
(docstrings, comments and data files aside). The exceptions, listed below: the list of
built-in plugins, where core finds them by name, and the columns sending a creature
writes (`behaviour.DESTINATION_WRITES`); a new one fails here."""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent / "ecs_tentacles"
FEATURES = re.compile(r"(?i)\b(locomotion|fur|goals?|guides?|terrain|threats?|director|herding)\b")
CORE = [*ROOT.glob("*.py")] + [
    p
    for d in ("creatures", "ground", "numeric", "output", "physics", "scene", "take")
    for p in (ROOT / d).rglob("*.py")
]

# (file, the name or string) still allowed, and why
ALLOWED = {
    # the list of built-in plugins: where core finds them by name
    **{
        ("scene/plugins.py", s): "built-in plugins"
        for s in (
            '"locomotion"',
            '"ecs_tentacles.locomotion.plugin:LocomotionPlugin"',
            '"ecs_tentacles.locomotion.suckers:SuckersPlugin"',
            '"fur"',
            '"ecs_tentacles.fur.plugin:FurPlugin"',
            '"threats"',
            '"ecs_tentacles.threats.plugin:ThreatsPlugin"',
            '"terrain"',
            '"ecs_tentacles.terrain.plugin:TerrainPlugin"',
            '"director"',
            '"ecs_tentacles.director.plugin:DirectorPlugin"',
            '"herding"',
            '"ecs_tentacles.herding.plugin:HerdingPlugin"',
        )
    },
    # the columns the Destinations entry (the locomotion plugin's goals) writes: named
    # once in core so a behaviour's or game mode's systems can declare them from a public
    # module (issue 55), not from the examples package or another feature
    **{
        ("behaviour.py", s): "what sending a creature writes"
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


def feature_names() -> set[tuple[str, str]]:
    """(file relative to the package, token) of every feature name core's code says."""
    found = set()
    for path in CORE:
        source = path.read_text()
        skip = _docstring_lines(ast.parse(source))
        for token in tokenize.generate_tokens(io.StringIO(source).readline):
            if token.type not in (tokenize.NAME, tokenize.STRING) or token.start[0] in skip:
                continue
            if FEATURES.search(token.string):
                found.add((str(path.relative_to(ROOT)), token.string))
    return found


def test_core_code_names_no_feature_but_what_is_listed() -> None:
    unexpected = feature_names() - set(ALLOWED)
    assert not unexpected, f"core names a feature: {sorted(unexpected)}"


def test_the_list_has_nothing_core_no_longer_says() -> None:
    stale = set(ALLOWED) - feature_names()
    assert not stale, f"remove from ALLOWED: {sorted(stale)}"
