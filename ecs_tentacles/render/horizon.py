"""What lies round the scene: the sky's colours and the distance fog that joins them to
the ground (the ground past a heightfield's edge is the terrain's own mesh, "beyond":
`ecs_tentacles.terrain.ground_meshes`, drawn `REACH` m out).
Fog starts a little past the point the camera looks at and is complete well before the
far plane, in the sky's horizon colour, so the plane's far edge is never seen.
"""

from __future__ import annotations

REACH = 4000.0  # m from the origin to the outer edge of the ground beyond the field
HORIZON = (0.78, 0.82, 0.85)  # the sky at the horizon, and the fog's colour
ZENITH = (0.36, 0.53, 0.76)  # the sky straight up
FOG_START = 1.5  # fog begins this many camera distances from the eye
FOG_END = 14.0  # and is complete at this many (at least FOG_END_MIN m)
FOG_END_MIN = 40.0


def fog_range(distance: float) -> tuple[float, float]:
    """(start, end) of the fog in metres from the eye, for a camera `distance` m from the
    point it looks at."""
    end = max(FOG_END * distance, FOG_END_MIN)
    return min(FOG_START * distance, 0.5 * end), end
