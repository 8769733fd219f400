"""Wedges: one bake per combination of parameter values, with an index of outputs.

    ecs-tentacles bake octopus --seconds 2 --wedge seed=1..8 \\
        --wedge 'creatures[0].tentacles.strength=20,25,30' --out wedge/{name}.usd

`PATH=VALUES`: PATH is a JSON path as the scene validator prints it
(`creatures[0].tentacles.strength`, `physics.fps`, `seed`); VALUES is `A..B`
(integers A to B) or a comma-separated list of JSON values (a bare word is a
string: `gait=cyclic,coordinated`). The bake runs the cross product, first
parameter slowest. Every variant's scene is validated before anything runs, so a
bad path or value is refused with the validator's one-line message.

Output names: `{name}` in `--out` becomes `PATH-VALUE` per parameter joined by `_`,
where brackets are dropped and anything but letters, digits, `.`, `+` and `-` in a
value becomes `_` (`seed-3_creatures0.tentacles.strength-25`). `wedge.json` beside
the outputs lists each output's file, parameters and SHA-256 (written atomically).
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.json_types import JsonValue
from ecs_tentacles.scene.load import load_scene_plugins
from ecs_tentacles.scene.validate import format_path

_TOKEN = re.compile(r'\.?([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]|\[("(?:[^"\\]|\\.)*")\]')
_RANGE = re.compile(r"^(-?\d+)\.\.(-?\d+)$")
MAX_VARIANTS = 10_000


class WedgeError(ValueError):
    """A bad `--wedge` argument or variant; one line."""


@dataclass(frozen=True)
class WedgeAxis:
    """One `--wedge PATH=VALUES`."""

    path: tuple[str | int, ...]
    values: tuple[object, ...]

    @property
    def text(self) -> str:
        return format_path(self.path)


@dataclass(frozen=True)
class Variant:
    """One combination: its values, its output name and its validated scene."""

    values: dict[str, object]
    name: str
    scene: dict[str, object]


def parse_parameter(text: str) -> WedgeAxis:
    """`PATH=VALUES` -> WedgeAxis (WedgeError naming the problem)."""
    path_text, sep, values_text = text.partition("=")
    if not sep or not path_text or not values_text:
        raise WedgeError(f"argument --wedge: expected PATH=VALUES, got {text!r}")
    path: list[str | int] = []
    at = 0
    while at < len(path_text):
        match = _TOKEN.match(path_text, at)
        if match is None or (at == 0 and path_text[0] == "."):
            raise WedgeError(f"argument --wedge: {path_text!r} is not a JSON path like a.b[0].c")
        word, index, quoted = match.groups()
        path.append(word if word else int(index) if index else json.loads(quoted))
        at = match.end()
    span = _RANGE.match(values_text)
    if span:
        low, high = int(span[1]), int(span[2])
        if high < low:
            raise WedgeError(f"argument --wedge: {path_text}: empty range {values_text}")
        if high - low + 1 > MAX_VARIANTS:  # refused before the range is made
            raise WedgeError(
                f"argument --wedge: {path_text}: {high - low + 1} values, more than {MAX_VARIANTS}"
            )
        values: list[object] = list(range(low, high + 1))
    else:
        values = [_value(v.strip()) for v in values_text.split(",")]
    return WedgeAxis(tuple(path), tuple(values))


def _value(text: str) -> JsonValue:
    try:
        value: JsonValue = json.loads(text)
    except ValueError:
        return text
    return value


def safe(text: str) -> str:
    """A file-name-safe form of a value."""
    return re.sub(r"[^A-Za-z0-9.+-]", "_", text)


def variant_name(values: dict[str, object]) -> str:
    """`PATH-VALUE` per parameter, joined by `_` (see the module docstring)."""
    parts = []
    for path, value in values.items():
        shown = value if isinstance(value, str) else json.dumps(value)
        parts.append(f"{safe(path.replace('[', '').replace(']', ''))}-{safe(shown)}")
    return "_".join(parts)


def variants(
    raw: dict[str, object],
    parameters: list[WedgeAxis],
    source: str = "",
    *,
    allow_systems: bool = False,
    scene_dir: Path | None = None,
) -> list[Variant]:
    """Every combination's validated scene (WedgeError/SceneError before any bake);
    `source` (the scene file) starts each SceneError line. Plugins from files are found
    in `scene_dir` and imported only with `allow_systems`, as for the scene itself."""
    count = 1
    for parameter in parameters:
        count *= len(parameter.values)
    if count > MAX_VARIANTS:
        raise WedgeError(f"argument --wedge: {count} variants, more than {MAX_VARIANTS}")
    out: list[Variant] = []
    names: dict[str, int] = {}
    for combination in itertools.product(*(p.values for p in parameters)):
        scene = copy.deepcopy(raw)
        values = {}
        for parameter, value in zip(parameters, combination, strict=True):
            _set(scene, parameter.path, value)
            values[parameter.text] = value
        try:
            loaded, _ = load_scene_plugins(scene, allow_systems=allow_systems, scene_dir=scene_dir)
        except SceneError as error:
            shown = ", ".join(f"{k}={json.dumps(v)}" for k, v in values.items())
            where = f"{source}: " if source else ""
            lines = [f"{where}{line} (wedge {shown})" for line in error.problems]
            raise SceneError(lines) from None
        name = variant_name(values)
        if name in names:
            raise WedgeError(f"argument --wedge: two variants are both named {name!r}")
        names[name] = len(out)
        out.append(Variant(values, name, loaded))
    return out


def _set(scene: Any, path: tuple[str | int, ...], value: Any) -> None:
    node = scene
    for depth, part in enumerate(path):
        here = format_path(path[: depth + 1])
        last = depth == len(path) - 1
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                size = len(node) if isinstance(node, list) else 0
                raise WedgeError(f"argument --wedge: {here}: no such item (the scene has {size})")
        elif not isinstance(node, dict):
            raise WedgeError(
                f"argument --wedge: {here}: {format_path(path[:depth])} is not an object"
            )
        if last:
            node[part] = value
        elif isinstance(part, str) and part not in node:
            node = node.setdefault(part, {})
        else:
            node = node[part]


MAX_NAME_BYTES = 255  # the longest file name common file systems take


def output_for(pattern: Path, name: str) -> Path:
    """The output file of variant `name`."""
    return pattern.with_name(pattern.name.replace("{name}", name))


def outputs_problem(pattern: Path, every: list[Variant]) -> str | None:
    """Why the outputs could not all be written (checked before any bake), or None."""
    for variant in every:
        out = output_for(pattern, variant.name)
        if len(out.name.encode()) > MAX_NAME_BYTES:
            return (
                f"argument --out: the file name of variant {variant.name!r} is"
                f" {len(out.name.encode())} bytes, more than the {MAX_NAME_BYTES} a file name"
                " may have (wedge fewer parameters or shorten the pattern)"
            )
    return None


def write_index(pattern: Path, base: dict[str, Any], rows: list[dict[str, Any]]) -> Path:
    """`wedge.json` beside the outputs: `base` facts plus one row per output with its
    SHA-256; written atomically."""
    for row in rows:
        row["sha256"] = hashlib.sha256(Path(row["file"]).read_bytes()).hexdigest()
        row["file"] = Path(row["file"]).name
    index = pattern.parent / "wedge.json"
    with atomic_file(index) as handle:
        handle.write((json.dumps({**base, "outputs": rows}, indent=2) + "\n").encode())
    return index
