"""The index of extension points (docs/extending/extension-points.md) lists every hook and
attribute of `Plugin` and `System`, every registry and event class in the package and every
entry-point group the project declares, and nothing the code no longer has.

Registries and events are found in the source (classes whose bases lead to `Registry` or
`Event`), so a new one anywhere in the package, in whatever folder, is found without
importing anything optional (GL, Blender, Ray)."""

from __future__ import annotations

import ast
import functools
import re
import tomllib
from pathlib import Path

import pytest

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.plugins import ENTRY_POINTS
from ecs_tentacles.system import System

ROOT = Path(__file__).resolve().parents[2]
INDEX = ROOT / "docs" / "extending" / "extension-points.md"
ROW = re.compile(r"^\| `([\w.]+)` \|", flags=re.M)

pytestmark = pytest.mark.skipif(not INDEX.exists(), reason="needs the source tree")


def listed() -> set[str]:
    """The names in the first column of the index's tables."""
    return set(ROW.findall(INDEX.read_text()))


def surface(cls: type) -> set[str]:
    """`Class.name` for each public method and attribute the class defines or annotates,
    and each attribute its instances get in `__init__`."""
    names = {n for n in vars(cls) if not n.startswith("_")} | set(cls.__annotations__)
    made = vars(cls()) if cls is Plugin else {"plugin": ""}  # System: `plugin` only
    return {f"{cls.__name__}.{n}" for n in names | set(made) if not n.startswith("_")}


@functools.cache
def class_bases() -> dict[str, set[str]]:
    """Every class of the package's source (top level) and the names of its bases."""
    bases: dict[str, set[str]] = {}
    for source in (ROOT / "ecs_tentacles").rglob("*.py"):
        for node in ast.parse(source.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef):
                for base in node.bases:
                    target = base.value if isinstance(base, ast.Subscript) else base
                    name = ast.unparse(target).rpartition(".")[2]
                    bases.setdefault(node.name, set()).add(name)
    return bases


def subclasses_in_source(*roots: str) -> set[str]:
    """Classes of the package's source whose bases lead, by name, to one of `roots`."""
    bases = class_bases()
    found = set(roots)
    grew = True
    while grew:
        more = {name for name, parents in bases.items() if parents & found} - found
        found |= more
        grew = bool(more)
    return found


def test_the_index_reads_as_a_table_of_names() -> None:
    names = listed()
    assert {"Plugin.build", "System.process", "Spheres", "GoalReached", ENTRY_POINTS} <= names


def test_every_plugin_and_system_hook_and_attribute_is_listed() -> None:
    expected = surface(Plugin) | surface(System)
    names = {name for name in listed() if name.startswith(("Plugin.", "System."))}
    assert expected - names == set(), "hooks or attributes the index does not list"
    assert names - expected == set(), "listed, but Plugin and System no longer have them"


def test_every_registry_and_event_is_listed() -> None:
    kinds = (subclasses_in_source("Registry") - {"Registry"}) | subclasses_in_source("Event")
    names = {name for name in listed() if "." not in name}
    assert kinds - names == set(), "registries or events the index does not list"
    assert names - kinds == set(), "listed, but no such registry or event in the package"


def test_every_entry_point_group_is_listed() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    groups = {ENTRY_POINTS, *project.get("entry-points", {})}
    assert groups <= listed()
