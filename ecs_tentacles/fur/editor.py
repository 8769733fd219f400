"""Editing fur as scene data: controls, their values and positions, keys; saving.

The document is the world's scene (``world.scene``: validated, defaults filled). Edits
that keep the set of controls (behaviour values, positions, keys) are written into the
document and straight into the world's stores, so the rig shows them on its next run;
edits that change the set (create, delete) rebuild the world from the document through
the `rebuild` callback the sandbox gives. A mirrored control's twin is edited through
its original: moving the twin moves the original to the mirrored place.

Moving a control re-assigns the fur's guides to their nearest control (thesis 4.3, the
rule `fur.build` uses), between rest positions in the creature frame.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.components import Creature
from ecs_tentacles.fur.components import Fur, FurControl
from ecs_tentacles.fur.controls import expand_mirrors, mirror_name, mirror_point, nearest_control
from ecs_tentacles.fur.stores import BEHAVIOURS, COLUMNS, FurData
from ecs_tentacles.numeric.keyframes import EASINGS, TrackSet, channels_from_keys
from ecs_tentacles.scene.save import save_scene

if TYPE_CHECKING:
    from pathlib import Path

    from ecs_tentacles.host import Host

VALUES = (*BEHAVIOURS, "emotion")
ATTRIBUTES = tuple(COLUMNS)  # keyable
SHAPES = ("sphere", "cube", "circle", "diamond", "arrow")
MIRRORS = ("none", "x", "y", "z")
KEY_TOLERANCE = 1e-6  # seconds: a key set at the time of another replaces it


class FurEditor:
    """The fur of one selected creature, edited in a world and in its scene document."""

    def __init__(self, world: Host, rebuild: Callable[[dict[str, object]], Host]):
        if world.scene is None:
            raise ValueError("the fur editor needs a world built from a scene")
        self.scene: dict[str, Any] = copy.deepcopy(world.scene)
        self.rebuild_world = rebuild
        self.world = world
        furry = self.furry_creatures()
        self.creature: str | None = furry[0] if furry else None
        self.control: str | None = None
        self.select_first_control()

    # -- the document ----------------------------------------------------------------
    def furry_creatures(self) -> list[str]:
        """Names of the scene's creatures that have fur."""
        return [c["name"] for c in self.scene["creatures"] if "fur" in c]

    def _creature_spec(self) -> dict[str, Any]:
        if self.creature is None:
            raise ValueError("no creature with fur is selected")
        for spec in self.scene["creatures"]:
            if spec["name"] == self.creature:
                found: dict[str, Any] = spec
                return found
        raise KeyError(f"no creature named {self.creature!r} in the scene")

    def fur_spec(self) -> dict[str, Any]:
        """The selected creature's `fur` entry of the document."""
        fur: dict[str, Any] = self._creature_spec()["fur"]
        return fur

    def control_names(self) -> list[str]:
        """Every control of the selected creature, mirrored twins after their originals."""
        if self.creature is None:
            return []
        return [c["name"] for c in expand_mirrors(self.fur_spec()["controls"])]

    def source(self, name: str) -> tuple[dict[str, Any], str | None]:
        """The document's control that makes `name`, and the mirror axis if `name` is a twin."""
        for control in self.fur_spec()["controls"]:
            if control["name"] == name:
                return control, None
            axis = control.get("mirror", "none")
            if axis != "none" and mirror_name(control["name"]) == name:
                return control, axis
        raise KeyError(f"no control named {name!r} on {self.creature!r}")

    def select(self, creature: str | None) -> None:
        """Edit `creature`'s fur (a name; None when it has none)."""
        self.creature = creature if creature in self.furry_creatures() else None
        self.select_first_control()

    def select_first_control(self) -> None:
        names = self.control_names()
        self.control = names[0] if names else None

    # -- the world -------------------------------------------------------------------
    def attach(self, world: Host) -> None:
        """Edit `world` from now on (after the sandbox rebuilt or reset it)."""
        self.world = world
        if self.control not in self.control_names():
            self.select_first_control()

    def _rebuild(self) -> None:
        self.attach(self.rebuild_world(copy.deepcopy(self.scene)))

    def entity(self) -> int:
        assert self.creature is not None
        return self.world.creature(self.creature)

    def rows(self) -> dict[str, int]:
        """Control name -> ControlStore row, for the selected creature."""
        fur = self.world.component(self.entity(), Fur)
        controls = (self.world.component(e, FurControl) for e in fur.controls)
        return {c.name: c.row for c in controls}

    def _twin_rows(self, name: str) -> list[tuple[int, str | None]]:
        """Rows showing `name`'s source control: (row, axis to mirror by or None)."""
        control, _ = self.source(name)
        rows = self.rows()
        mirror = control.get("mirror", "none")
        out: list[tuple[int, str | None]] = [(rows[control["name"]], None)]
        if mirror != "none":
            out.append((rows[mirror_name(control["name"])], mirror))
        return out

    def assignment(self) -> np.ndarray:
        """The control name each of the selected creature's guides follows (guide order)."""
        fur = self.world.component(self.entity(), Fur)
        names = {row: name for name, row in self.rows().items()}
        g = self.world.resource(FurData).guides
        mine = np.flatnonzero(g.fur_row == fur.row)
        return np.array([names[int(r)] for r in g.control_row[mine]])

    # -- creating and deleting -----------------------------------------------------------
    def create(
        self,
        name: str,
        count: int = 1,
        shape: str = "sphere",
        colour: tuple[float, ...] = (1.0, 0.8, 0.0),
        mirror: str = "none",
    ) -> list[str]:
        """Add `count` controls (name, name_1, ...) on the mantle; returns their names."""
        if not name or count < 1 or shape not in SHAPES or mirror not in MIRRORS:
            raise ValueError(f"bad control: name {name!r}, count {count}, {shape}, {mirror}")
        spec = self.fur_spec()
        taken = set(self.control_names())
        info = self.world.component(self.entity(), Creature)
        radius, half = info.mantle_radius, info.mantle_height / 2
        made = []
        for k in range(count):
            base = name if count == 1 else f"{name}_{k}"
            label, n = base, 1
            while label in taken or (mirror != "none" and mirror_name(label) in taken):
                label, n = f"{base}_{n}", n + 1
            angle = (np.pi / 3 if mirror != "none" else 0.0) + 2 * np.pi * k / count
            position = [radius * np.cos(angle), radius * np.sin(angle), 0.5 * half]
            control = {"name": label, "shape": shape, "colour": [float(c) for c in colour]}
            control |= {"position": [round(float(x), 4) for x in position], "mirror": mirror}
            spec["controls"].append(_defaults(control))
            taken |= {label, mirror_name(label)}
            made.append(label)
        self._rebuild()
        self.control = made[0]
        return made

    def delete(self, name: str) -> None:
        """Remove control `name` (with its mirrored twin); a fur keeps at least one."""
        control, _ = self.source(name)
        controls = self.fur_spec()["controls"]
        if len(controls) == 1:
            raise ValueError("a fur needs at least one control")
        controls.remove(control)
        self._rebuild()
        self.select_first_control()

    # -- editing -------------------------------------------------------------------------
    def value(self, name: str, attribute: str) -> Any:
        """The world's current value of a control's attribute (position: creature frame)."""
        row = self.rows()[name]
        store = self.world.resource(FurData).controls
        if attribute == "position":
            return store.position[row].copy()
        return float(getattr(store, attribute)[row])

    def set_value(self, name: str, attribute: str, value: float) -> None:
        """Set lift, aim, direction, random, dynamic or emotion (0..1) of a control."""
        if attribute not in VALUES:
            raise ValueError(f"not a control value: {attribute!r}")
        value = float(np.clip(value, 0.0, 1.0))
        control, _ = self.source(name)
        control[attribute] = value
        column = getattr(self.world.resource(FurData).controls, attribute)
        for row, _axis in self._twin_rows(name):
            column[row] = value

    def set_position(self, name: str, position: np.ndarray | list[float]) -> None:
        """Move a control (creature frame) and its twin; guides re-pick their nearest."""
        control, axis = self.source(name)
        point = [float(x) for x in position]
        control["position"] = mirror_point(point, axis) if axis else point
        store = self.world.resource(FurData).controls
        for row, mirror in self._twin_rows(name):
            placed = mirror_point(control["position"], mirror) if mirror else control["position"]
            store.position[row] = placed
            store.rest_position[row] = placed
        self._reassign()

    def _reassign(self) -> None:
        fur = self.world.component(self.entity(), Fur)
        rows = np.array(list(self.rows().values()))
        g = self.world.resource(FurData).guides
        mine = np.flatnonzero(g.fur_row == fur.row)
        if any("control" in guide for guide in self.fur_spec()["guides"]):
            return  # guides that name their control keep it (their rows are not tracked)
        rests = self.world.resource(FurData).controls.rest_position[rows]
        g.control_row[mine] = rows[nearest_control(g.root[mine], rests)]
        self.world.resource(FurData).touch()

    # -- keys --------------------------------------------------------------------------
    def keys(self, name: str, attribute: str) -> list[dict[str, Any]]:
        """The document's keys of `name`'s attribute (its source's, for a twin)."""
        control, axis = self.source(name)
        for track in control["tracks"]:
            if track["attribute"] == attribute:
                keys: list[dict[str, Any]] = track["keys"]
                if axis and attribute == "position":
                    return [k | {"value": mirror_point(k["value"], axis)} for k in keys]
                return keys
        return []

    def set_key(self, name: str, attribute: str, time: float, easing: str = "ease") -> None:
        """Key the attribute's current value at `time` with `easing` (replacing one there)."""
        if attribute not in ATTRIBUTES or easing not in EASINGS:
            raise ValueError(f"cannot key {attribute!r} with easing {easing!r}")
        control, axis = self.source(name)
        value = self.value(name, attribute)
        if attribute == "position":
            value = [float(x) for x in value]
            value = mirror_point(value, axis) if axis else value
        tracks = control["tracks"]
        track = next((t for t in tracks if t["attribute"] == attribute), None)
        if track is None:
            track = {"attribute": attribute, "keys": []}
            tracks.append(track)
        keys = [k for k in track["keys"] if abs(k["time"] - time) > KEY_TOLERANCE]
        keys.append({"time": round(float(time), 6), "value": value, "easing": easing})
        track["keys"] = sorted(keys, key=lambda k: k["time"])
        self._sync_tracks()

    def delete_key(self, name: str, attribute: str, time: float, within: float) -> bool:
        """Delete the key nearest `time` (at most `within` s away); False if none."""
        control, _ = self.source(name)
        for track in control["tracks"]:
            if track["attribute"] != attribute or not track["keys"]:
                continue
            times = np.array([k["time"] for k in track["keys"]])
            nearest = int(np.argmin(np.abs(times - time)))
            if abs(times[nearest] - time) > within:
                return False
            del track["keys"][nearest]
            if not track["keys"]:
                control["tracks"].remove(track)
            self._sync_tracks()
            return True
        return False

    def key_times(self) -> list[float]:
        """Times of every key of every control of the selected creature (sorted)."""
        if self.creature is None:
            return []
        controls = expand_mirrors(self.fur_spec()["controls"])
        return sorted({k["time"] for c in controls for t in c["tracks"] for k in t["keys"]})

    def _sync_tracks(self) -> None:
        """The world's tracks rebuilt from the document (every furry creature's)."""
        channels = []
        for spec in self.scene["creatures"]:
            if "fur" not in spec:
                continue
            fur = self.world.component(self.world.creature(spec["name"]), Fur)
            rows = {
                c.name: c.row for c in (self.world.component(e, FurControl) for e in fur.controls)
            }
            for control in expand_mirrors(spec["fur"]["controls"]):
                for track in control["tracks"]:
                    columns = COLUMNS[track["attribute"]]
                    channels += channels_from_keys(rows[control["name"]], columns, track["keys"])
        self.world.resource(FurData).tracks = channels
        self.world.resource(FurData).touch()

    def track_value(self, name: str, attribute: str, time: float) -> np.ndarray:
        """What fur.tracks gives for a control's attribute at `time` (as the rig plays it)."""
        keys = self.keys(name, attribute)
        columns = COLUMNS[attribute]
        return TrackSet(channels_from_keys(0, columns, keys)).evaluate(time)

    # -- saving --------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write the document (validated) to `path` atomically; returns the path."""
        return save_scene(self.scene, path)


def _defaults(control: dict[str, Any]) -> dict[str, Any]:
    """A new control with the schema's defaults (values 0, emotion 1, no tracks)."""
    values = {k: 0.0 for k in VALUES} | {"emotion": 1.0}
    return {"size": 0.03, **values, "tracks": [], **control}
