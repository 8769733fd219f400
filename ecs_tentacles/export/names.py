"""The names exports give prims and nodes: unique in the whole file, after the creature.

Importers name objects globally (Blender: `link9`, `link9.001`, ... with suffixes in
no useful order), so every name below a creature starts with the creature's and the
path to it: the take's `octopus/tentacles/t6/link9/sucker0` becomes the prim path
`octopus/octopus_tentacles/octopus_t6/octopus_t6_link9/octopus_t6_link9_sucker0`.
Folders (`FOLDERS`) get the creature's name but do not lengthen the names below them.
The take's own names are unchanged (the take format and its hashes do not move).
"""

from __future__ import annotations

FOLDERS = frozenset({"tentacles", "suckers", "goals", "fur", "materials"})


def unique_path(name: str, folders: frozenset[str] = FOLDERS) -> str:
    """A take name `<creature>/...` as a path of unique names (see the module doc);
    `folders` are the group names (a plugin's track folder is one too)."""
    creature, *rest = name.split("/")
    out, stem = [creature], creature
    for part in rest:
        if part in folders:
            out.append(f"{creature}_{part}")
        else:
            stem = f"{stem}_{part}"
            out.append(stem)
    return "/".join(out)


def unique_leaf(name: str, folders: frozenset[str] = FOLDERS) -> str:
    """The last name of `unique_path(name, folders)`."""
    return unique_path(name, folders).rsplit("/", 1)[-1]


def part(creature: str, what: str) -> str:
    """A creature's own part: `octopus_skeleton`, `octopus_skin`, `octopus_animation`."""
    return f"{creature}_{what}"
