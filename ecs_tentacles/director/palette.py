"""The palette: creatures and threats the director can place.

`presets(scene_dir)` lists, in this order:

* every creature of the bundled scenes (`<scene>/<creature>`; one of each body; the
  octopus first);
* the crowd generator's species (`species 1` ... : `ecs_tentacles.creator.crowd`), the
  bodies `ecs-tentacles crowd` mixes;
* creatures exported from the creator (`ecs-tentacles create --out ...`): every scene
  file in a `creatures/` folder beside the scene, in the working folder, or in
  `$ECS_TENTACLES_CREATURES`, each of its creatures;
* threats (the roach): a marked thing that frightens creatures (`threats` plugin).

A preset's `entry` is a scene-style creature dict (`World.spawn` validates it) or, for
a threat, `{"threat": name}`. Files that do not load are skipped with one logged line.
"""

from __future__ import annotations

import copy
import json
import logging
import os
from dataclasses import dataclass
from pathlib import Path

from ecs_tentacles.scene.load import bundled_scene, bundled_scene_names, read_scene_json

log = logging.getLogger("ecs_tentacles.director")

SPECIES = 8  # generator species listed
SPECIES_SEED = 0
FOLDER = "creatures"  # exported creatures beside a scene or in the working folder
ENVIRONMENT = "ECS_TENTACLES_CREATURES"
THREAT = "roach"


@dataclass(frozen=True)
class Preset:
    """One thing the palette places: `label` in the list, `source` (where it is from),
    `entry` (a creature entry, or {"threat": name})."""

    label: str
    source: str
    entry: dict[str, object]

    @property
    def is_threat(self) -> bool:
        return "threat" in self.entry and "tentacles" not in self.entry

    @property
    def threat(self) -> str:
        """The name a threat preset drops its threat by."""
        return str(self.entry["threat"])

    def creature(self) -> dict[str, object]:
        """A fresh copy of the creature entry (no position, goals or heading of its scene)."""
        entry = copy.deepcopy(self.entry)
        for key in ("position", "goals", "heading_deg"):
            entry.pop(key, None)
        return entry


def presets(scene_dir: str | os.PathLike[str] | None = None) -> list[Preset]:
    """Every preset (module docstring), bundled first."""
    found = _bundled() + _species()
    for folder in _folders(scene_dir):
        found += _exported(folder)
    found.append(Preset(THREAT, "threats", {"threat": THREAT}))
    return found


def _body_key(entry: dict[str, object]) -> str:
    body = {k: entry.get(k) for k in ("mantle", "tentacles", "fur")}
    return json.dumps(body, sort_keys=True)


def _bundled() -> list[Preset]:
    out, seen = [], set()
    for name in sorted(bundled_scene_names(), key=lambda n: (n != "octopus", n)):
        data = read_scene_json(bundled_scene(name))
        for creature in data.get("creatures", []) if isinstance(data, dict) else []:
            key = _body_key(creature)
            if key in seen:
                continue
            seen.add(key)
            label = f"{name}/{creature.get('name', 'creature')}"
            out.append(Preset(label, f"bundled scene {name}", copy.deepcopy(creature)))
    return out


def _species() -> list[Preset]:
    from ecs_tentacles.creator.crowd import species_creatures

    return [
        Preset(f"species {k}", "the crowd generator", entry)
        for k, entry in enumerate(species_creatures(SPECIES, SPECIES_SEED), start=1)
    ]


def _folders(scene_dir: str | os.PathLike[str] | None) -> list[Path]:
    folders = [Path(scene_dir) / FOLDER] if scene_dir is not None else []
    folders.append(Path.cwd() / FOLDER)
    if os.environ.get(ENVIRONMENT):
        folders.append(Path(os.environ[ENVIRONMENT]))
    unique: list[Path] = []
    for folder in folders:
        if folder.is_dir() and folder.resolve() not in [u.resolve() for u in unique]:
            unique.append(folder)
    return unique


def _exported(folder: Path) -> list[Preset]:
    out = []
    for path in sorted(folder.glob("*.json")):
        try:
            data = read_scene_json(path)
        except Exception as exc:  # a bad file is skipped, said once
            log.warning("palette: %s skipped: %s", path, " ".join(str(exc).split()))
            continue
        creatures = data.get("creatures", []) if isinstance(data, dict) else []
        for creature in creatures:
            if isinstance(creature, dict):
                label = f"{path.stem}/{creature.get('name', 'creature')}"
                out.append(Preset(label, str(path), copy.deepcopy(creature)))
    return out
