"""emotion: fear or aggression that rises near a threat and raises the fur (piloerection).

Dangers come from the plugins that make them (`ecs_tentacles.behaviour.dangers`: the
threats plugin's path threats, moved by its `threats` system, and creatures marked
`threat`); without one nothing frightens. A
creature with an `Emotion` is roused while any threat other than itself is within its
radius of its mantle. Its emotion follows a critically damped response toward 1
(roused) or 0 (calm), reaching 90 % in
`rise` or `decay` seconds: it starts slowly and settles slowly (slow-in, slow-out).
The level shown is ``state - anticipation * speed / omega_rise``: before it rises it
first dips (the fur flattens a little, anticipation), before it falls it first swells.
Each of the creature's controls gets ``level * control.emotion * fur.piloerection``
added to its lift and random (clipped to 0..1 by the rig). No emotions: nothing done.

Reads: `dangers(world)` (positions), Transform store (mantles of emotional and threat
creatures), EmotionStore settings and state. Writes: EmotionStore (state, speed, level,
threatened), ControlStore (drive_lift, drive_random).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.behaviour import DANGERS_MOVED, dangers
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

NINETY_PERCENT = 3.8897  # omega * t at which a critically damped step reaches 90 %


class EmotionSystem(System):
    name = "emotion"
    stage = "animate"
    after = (DANGERS_MOVED,)
    before = ("rig",)
    calls_hooks = True  # the Dangers entries (`behaviour.dangers`)
    reads = (
        "transforms.pos",
        "fur.emotions",
        "fur.sets",
        "fur.controls.emotion",
        "fur.controls.emotion_row",
        "fur.controls.fur_row",
    )
    writes = ("fur.emotions", "fur.controls.drive_lift", "fur.controls.drive_random")

    def process(self, world: Host, dt: float) -> None:
        fur = world.resource(FurData)
        e = fur.emotions
        if not len(e):
            return
        sources, owners = dangers(world)  # none without a plugin that makes them
        if len(sources):
            here = world.transforms.pos[e.body_row]
            distance = np.linalg.norm(here[:, None, :] - sources[None, :, :], axis=2)
            distance[owners[None, :] == e.creature[:, None]] = np.inf  # not afraid of itself
            near = (distance < e.radius[:, None]).any(axis=1)
        else:
            near = np.zeros(len(e), dtype=bool)
        target = near.astype(np.float64)
        rise = NINETY_PERCENT / e.rise
        omega = np.where(target > e.state, rise, NINETY_PERCENT / e.decay)
        # exact step of x'' = omega^2 (target - x) - 2 omega x' over dt
        error, speed = e.state - target, e.speed
        grow = speed + omega * error
        fade = np.exp(-omega * dt)
        e.state = target + (error + grow * dt) * fade
        e.speed = (speed - omega * grow * dt) * fade
        e.level = np.clip(e.state - e.anticipation * e.speed / rise, -1.0, 1.0)
        e.threatened = near
        c = fur.controls
        if not len(c):
            return
        roused = np.where(c.emotion_row >= 0, e.level[np.maximum(c.emotion_row, 0)], 0.0)
        roused = roused * c.emotion
        c.drive_lift = roused * fur.sets.erect_lift[c.fur_row]
        c.drive_random = roused * fur.sets.erect_random[c.fur_row]
