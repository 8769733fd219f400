"""The predator's body as the renderer draws it: spheres and ellipsoids (`Marker`s).

    predator_body(world, game)   # [Marker, ...]: body, head, snout, ears, tail

A sheepdog-sized beast (about 0.7 m long, 0.5 m tall), brick red with a pale snout,
facing where it goes (`HerdingGame.state.heading`), big enough to pick out from across
a level; it crouches lower while it runs. The markers are axis-aligned ellipsoids, so
the parts that would need turning (body, head) are round and the direction shows in
where the head, snout, ears and tail sit.

Reads: `HerdingGame` (predator, heading, running), the ground's height. Writes: nothing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.render.registries import Marker

if TYPE_CHECKING:
    from ecs_tentacles.herding.game import HerdingGame
    from ecs_tentacles.host import Host

COAT = (0.72, 0.16, 0.08, 1.0)  # brick red: apart from sand, grass and the creatures
PALE = (0.95, 0.88, 0.75, 1.0)
DARK = (0.12, 0.05, 0.03, 1.0)
# (forward, sideways, up) metres of each part from the point under the body, its size
PARTS = (
    ((0.0, 0.0, 0.26), 0.22, COAT),  # body
    ((-0.2, 0.0, 0.26), 0.18, COAT),  # haunch
    ((0.28, 0.0, 0.42), 0.15, COAT),  # head
    ((0.42, 0.0, 0.39), 0.07, PALE),  # snout
    ((0.26, 0.09, 0.57), 0.055, DARK),  # ears
    ((0.26, -0.09, 0.57), 0.055, DARK),
    ((-0.42, 0.0, 0.34), 0.06, PALE),  # tail's tip
    ((0.1, 0.1, 0.08), 0.07, DARK),  # paws
    ((0.1, -0.1, 0.08), 0.07, DARK),
    ((-0.2, 0.1, 0.08), 0.07, DARK),
    ((-0.2, -0.1, 0.08), 0.07, DARK),
)


def predator_body(world: Host, game: HerdingGame) -> list[Marker]:
    """The predator's parts, placed on the ground where it stands, facing its heading."""
    heading = game.state.heading
    forward = np.array([np.cos(heading), np.sin(heading)])
    side = np.array([-forward[1], forward[0]])
    xy = game.predator
    base = float(ground_of(world).height(xy[None])[0])
    crouch = 0.8 if game.sprinting else 1.0
    out = []
    for (ahead, across, up), size, rgba in PARTS:
        at = xy + ahead * forward + across * side
        z = base + up * (crouch if up > 0.1 else 1.0)
        out.append(Marker(np.array([[at[0], at[1], z]]), (size, size, size), rgba))
    return out
