"""No import circle between the engine's modules, type-only imports included.

Every `import` and `from ... import` statement of every module of `ecs_tentacles` and
of the example plugins (`systems/ecs_tentacles_examples`) is read with `ast`: those at the
top, under `if TYPE_CHECKING:` and inside functions alike. An import of `a.b.c` (or
`from a.b import c` where `c` is a module) is an edge to `a.b.c`; the packages above
it are not counted. A circle is named module by module (a -> b -> c -> a).
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = {
    "ecs_tentacles": ROOT / "ecs_tentacles",
    "ecs_tentacles_examples": ROOT / "systems" / "ecs_tentacles_examples",
}
WORLD = "ecs_tentacles.world"

Graph = dict[str, set[str]]


def _modules() -> dict[str, tuple[Path, bool]]:
    """Every module by dotted name: its file and whether it is a package's __init__."""
    found: dict[str, tuple[Path, bool]] = {}
    for prefix, folder in PACKAGES.items():
        for path in folder.rglob("*.py"):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            package = parts[-1] == "__init__"
            found[".".join([prefix, *(parts[:-1] if package else parts)])] = (path, package)
    return found


def _imported(name: str, path: Path, package: bool, modules: set[str]) -> Iterator[str]:
    """The engine modules that `name` imports, anywhere in its file."""
    here = name if package else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names if alias.name in modules)
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: from the module's package, one level up per extra dot
                parts = here.split(".")[: len(here.split(".")) - node.level + 1]
                base = ".".join([*parts, *([node.module] if node.module else [])])
            else:
                base = node.module or ""
            for alias in node.names:
                if f"{base}.{alias.name}" in modules:
                    yield f"{base}.{alias.name}"
                elif base in modules:
                    yield base


def import_graph() -> Graph:
    """Module -> the engine modules it imports."""
    modules = _modules()
    names = set(modules)
    return {
        name: set(_imported(name, path, package, names)) - {name}
        for name, (path, package) in modules.items()
    }


def circles(graph: Graph) -> list[list[str]]:
    """One circle (a -> ... -> a) per strongly connected group of modules (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    groups: list[set[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for other in sorted(graph[node]):
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in stack:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            group = set()
            while True:
                member = stack.pop()
                group.add(member)
                if member == node:
                    break
            if len(group) > 1:
                groups.append(group)

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return [_circle_in(graph, group) for group in groups]


def _circle_in(graph: Graph, group: set[str]) -> list[str]:
    """The shortest circle through the group's first module (by name), breadth first."""
    start = min(group)
    paths = {start: [start]}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for other in sorted(graph[node] & group):
                if other == start:
                    return [*paths[node], start]
                if other not in paths:
                    paths[other] = [*paths[node], other]
                    following.append(other)
        frontier = following
    raise AssertionError(f"no circle through {start}")  # a strongly connected group has one


def _report(found: list[list[str]]) -> str:
    return "\n".join(f"import circle ({len(c) - 1} modules): {' -> '.join(c)}" for c in found)


def test_the_scan_sees_type_only_and_function_level_imports() -> None:
    graph = import_graph()
    assert "ecs_tentacles.host" in graph["ecs_tentacles.system"]  # under TYPE_CHECKING
    assert "ecs_tentacles.creatures.loading" in graph[WORLD]  # inside World.from_scene
    assert "ecs_tentacles.locomotion.systems.suckers" in graph["ecs_tentacles.locomotion.suckers"]
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c", "a"]]


def test_no_import_circle() -> None:
    found = circles(import_graph())
    assert not found, _report(found)


def test_nothing_world_imports_imports_it_back() -> None:
    graph = import_graph()
    below = graph[WORLD] - {"ecs_tentacles.creatures.loading"}  # the loader sits above
    back = sorted(m for m in below if WORLD in graph[m])
    assert not back, f"imported by world.py and importing it: {back}"
    assert WORLD not in graph["ecs_tentacles.creatures.loading"]


CORE = (
    "ecs_tentacles.world", "ecs_tentacles.creatures.loading", "ecs_tentacles.host",
    "ecs_tentacles.settings", "ecs_tentacles.schedule", "ecs_tentacles.system",
    "ecs_tentacles.plugin", "ecs_tentacles.scene.plugins", "ecs_tentacles.store",
    "ecs_tentacles.components",
    "ecs_tentacles.creatures.body", "ecs_tentacles.scene.construction", "ecs_tentacles.physics",
    "ecs_tentacles.snapshot", "ecs_tentacles.events", "ecs_tentacles.scene",
    "ecs_tentacles.physics.systems",
)  # fmt: skip
FEATURES = ("locomotion", "fur", "threats", "record", "clips")


def _within(module: str, prefixes: tuple[str, ...]) -> bool:
    return any(module == p or module.startswith(p + ".") for p in prefixes)


def test_core_imports_no_feature_nor_its_systems() -> None:
    """The contracts leave out imports under TYPE_CHECKING; this scan counts them too. A
    feature's systems are in its package (`ecs_tentacles.<feature>.systems`)."""
    graph = import_graph()
    features = tuple(f"ecs_tentacles.{f}" for f in (*FEATURES, "render")) + (
        "ecs_tentacles_examples",
    )
    wrong = sorted(
        (source, target)
        for source, targets in graph.items()
        if _within(source, CORE)
        for target in targets
        if _within(target, features)
    )
    assert not wrong, "core imports a feature: " + ", ".join(f"{s} -> {t}" for s, t in wrong)
