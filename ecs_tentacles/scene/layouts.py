"""`Layouts`: each creature entry's layout, worked out once per load and handed to all
who need it.

A load places every creature several times over: the physical checks (on the plane:
weights, servos, overlaps), the terrain's check that nobody starts inside a rock and
the build itself (on the world's ground). They all read one `Layouts` (the loader
makes it, `world.layouts` holds it while the world is built), so an entry's tentacle
settings and shapes are worked out once, and its layout on shaped ground is the plane
layout raised (`CreatureLayout.on`).

    layouts = Layouts()
    flat = layouts.on_plane(spec)           # the physical checks
    built = layouts.on(spec, ground)        # the terrain's checks, then the build

An entry is known by identity; one whose `position` or `heading_deg` changed since
(the physical checks moving overlapping creatures apart) is worked out again.
Reads the entries; writes nothing but its own table.
"""

from __future__ import annotations

from ecs_tentacles.ground import Ground
from ecs_tentacles.scene.construction import CreatureLayout, creature_layout
from ecs_tentacles.scene.spec import CreatureSpec

Placed = tuple[tuple[float, ...], float]  # an entry's position and heading


class Layouts:
    """Creature layouts by entry, on the plane and on grounds (module docstring)."""

    def __init__(self) -> None:
        # by id(entry): the entry (kept, so its id is not reused), where it was placed,
        # its plane layout and its layouts on grounds by id(ground) (the ground kept)
        self._made: dict[int, tuple[CreatureSpec, Placed, CreatureLayout]] = {}
        self._grounds: dict[tuple[int, int], tuple[Ground, CreatureLayout]] = {}
        self.worked_out = 0  # plane layouts made (a test counts them)

    def on_plane(self, spec: CreatureSpec) -> CreatureLayout:
        """`spec`'s layout on the plane z = 0 (worked out the first time it is asked)."""
        placed = (tuple(spec["position"]), spec["heading_deg"])
        found = self._made.get(id(spec))
        if found is not None and found[1] == placed:
            return found[2]
        layout = creature_layout(spec)
        self.worked_out += 1
        self._made[id(spec)] = (spec, placed, layout)
        if found is not None:  # it moved: its layouts on grounds are stale
            for key in [key for key in self._grounds if key[0] == id(spec)]:
                del self._grounds[key]
        return layout

    def on(self, spec: CreatureSpec, ground: Ground) -> CreatureLayout:
        """`spec`'s layout on `ground` (`CreatureLayout.on`): the plane layout, raised
        onto shaped ground once."""
        flat = self.on_plane(spec)
        if not flat.resting or ground.extent is None:
            return flat
        key = (id(spec), id(ground))  # (the ground is kept with it: its id stays its own)
        if key not in self._grounds:
            self._grounds[key] = (ground, flat.on(ground))
        return self._grounds[key][1]

    def clear(self) -> None:
        """Forget every layout (a built crowd's would only take memory)."""
        self._made.clear()
        self._grounds.clear()

    def __len__(self) -> int:
        return len(self._made)
