"""Crowd avoidance: creatures steer around each other instead of crawling into contact.

    world.resource(Avoidance).enabled = False          # the whole scene crawls straight
    scene: "avoidance": {"enabled": false}             # the same, from the scene
    creature: "avoid": false                           # this one crawls straight (others
                                                       # still steer around it)

A social-force term, whole-array work over every pair of creatures near each other: each
creature has a personal circle on the ground (`personal_radius`: its mantle radius plus
its longest tentacle: crawling, the tentacles lie spread out); the pairs whose circles
come within the scene's `range` of each other are found by the same near-pair search the
contact proxies use (`ecs_tentacles.physics.pairs.near_pairs`: every pair in small
crowds, a k-d tree in large ones). A neighbour pushes a creature away along the line
between them and to its right (both sides of a head-on meeting step aside the same way
and pass), more when the circles are closer (zero at `range`, one at touch, up to two
overlapped) and more when the neighbour is ahead of where it is going than behind it.
The sum, times `strength`, is the creature's `bend`: added to the unit direction toward
its steer point, it is the direction the creature crawls (`bent`: tentacle selection's
push/pull choice and strokes, and the kinematic replay's heading). It fades out within a
personal radius of the goal, so a creature still reaches a goal someone stands beside.

A creature with no neighbour within `range` gets exactly zero and crawls exactly as
without avoidance (bit for bit): scenes whose creatures stay apart do not change.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ecs_tentacles.numeric.optional_kernels import OptionalKernels
from ecs_tentacles.physics.pairs import near_pairs
from ecs_tentacles.scene.construction import creature_layout
from ecs_tentacles.scene.schema import fragment
from ecs_tentacles.scene.spec import creature_specs

BEHIND = 0.3  # a neighbour straight behind weighs this much of one straight ahead
SIDESTEP = 1.0  # the push to the right (keep right), relative to the push away
KERNELS = OptionalKernels("ecs_tentacles.locomotion.avoidance_kernels", "ECS_TENTACLES_AVOIDANCE")
PairFinder = Callable[[np.ndarray, np.ndarray, float], tuple[np.ndarray, np.ndarray]]
_SCENE = fragment("ecs_tentacles.locomotion", "locomotion")["scene"]["avoidance"]


def _default(key: str) -> float:
    return float(_SCENE["properties"][key]["default"])


@dataclass
class Avoidance:
    """`world.resource(Avoidance)`: the scene's avoidance settings (`avoidance` key)."""

    provided_by = "locomotion"

    enabled: bool = bool(_default("enabled"))
    range: float = _default("range")  # m between personal circles where it starts
    strength: float = _default("strength")

    def configure(self, scene: Mapping[str, object]) -> None:
        """Take the scene's `avoidance` object (its defaults where it says nothing)."""
        given = scene.get("avoidance")
        if not isinstance(given, Mapping):
            given = {}
        self.enabled = bool(given.get("enabled", _default("enabled")))
        self.range = float(given.get("range", _default("range")))
        self.strength = float(given.get("strength", _default("strength")))


def personal_radius(
    mantle_radius: np.ndarray, tentacle_creature: np.ndarray, tentacle_length: np.ndarray
) -> np.ndarray:
    """(creatures,) each creature's personal circle: mantle radius + its longest tentacle
    (tentacles given by their creature row and length)."""
    longest = np.zeros(len(mantle_radius))
    np.maximum.at(longest, tentacle_creature, tentacle_length)
    return mantle_radius + longest


def bend(
    pos: np.ndarray,
    radius: np.ndarray,
    heading: np.ndarray,
    steering: np.ndarray,
    to_goal: np.ndarray,
    reach: float,
    strength: float,
    pairs: PairFinder = near_pairs,
) -> np.ndarray:
    """(n, 2) each creature's avoidance term (module doc); zero where none applies.

    `pos` (n, 2): mantles on the ground; `radius` (n,): personal circles; `heading`
    (n, 2): unit directions toward where each crawls (zero: going nowhere); `steering`
    (n,) bool: who steers (the others are only avoided); `to_goal` (n,): ground distance
    to the steer point; `reach`: the scene's range (m); `strength`: its gain; `pairs`:
    what finds the neighbours (`near_pairs`, or a `NearPairCache` kept between frames).
    """
    out = np.zeros((len(pos), 2))
    if len(pos) < 2 or not steering.any() or strength == 0.0:
        return out
    a, b = pairs(pos, radius, reach)
    fast = KERNELS.get()
    if fast is not None:  # the same numbers, pair by pair
        fast.bend_pairs(pos, radius, heading, steering, to_goal, a, b, float(reach),
                        float(strength), BEHIND, SIDESTEP, out)  # fmt: skip
        return out
    keep = steering[a]
    a, b = a[keep], b[keep]
    if not len(a):
        return out
    d = pos[b] - pos[a]
    distance = np.hypot(d[:, 0], d[:, 1])
    toward = d / np.maximum(distance, 1e-9)[:, None]  # unit, a -> b
    gap = distance - radius[a] - radius[b]
    push = np.minimum(np.maximum(1.0 - gap / reach, 0.0), 2.0)  # `np.clip`'s numbers
    push *= push
    ahead = np.einsum("ij,ij->i", toward, heading[a])  # cos of the neighbour off the way
    weight = push * (BEHIND + (1.0 - BEHIND) * 0.5 * (1.0 + ahead))
    right = np.empty_like(toward)
    right[:, 0], right[:, 1] = toward[:, 1], -toward[:, 0]
    force = (SIDESTEP * np.maximum(ahead, 0.0)[:, None] * right - toward) * weight[:, None]
    np.add.at(out, a, force)
    fade = np.clip(to_goal / np.maximum(radius, 1e-9), 0.0, 1.0)  # near the goal: let it in
    out *= (strength * fade)[:, None]
    return out


def turned(term: np.ndarray) -> np.ndarray:
    """(n,) bool: the rows of avoidance `term` (n, 2) that turn a creature (not zero).
    Two compares, not `np.any(term != 0, axis=1)`: a tenth of the time, the same rows."""
    mask: np.ndarray = (term[:, 0] != 0.0) | (term[:, 1] != 0.0)
    return mask


def bent(to_goal: np.ndarray, term: np.ndarray) -> np.ndarray:
    """`to_goal` (n, 2 or 3: toward each steer point) turned by avoidance `term` (n, 2):
    unit direction + term, at the length of `to_goal`'s ground part. Rows whose term is
    zero are returned as they were, bit for bit (the same array when every row is)."""
    rows = np.flatnonzero(turned(term))
    if not len(rows):
        return to_goal
    out = to_goal.copy()
    length = np.hypot(to_goal[rows, 0], to_goal[rows, 1])
    out[rows, :2] += length[:, None] * term[rows]
    return out


def meeting_reach(scene: Mapping[str, object]) -> list[float] | None:
    """Per creature of `scene`, its personal radius and half the range: two creatures
    steer each other exactly when their mantles come within the sum of theirs (their
    personal circles within the range; `Plugin.meeting_reach`); None with avoidance off."""
    settings = Avoidance()
    settings.configure(scene)
    if not settings.enabled:
        return None
    out = []
    for creature in creature_specs(scene):
        layout = creature_layout(creature)  # the shapes the built creature has
        longest = max((shape.length for shape in layout.shapes), default=0.0)
        out.append(float(creature["mantle"]["radius"]) + longest + 0.5 * settings.range)
    return out
