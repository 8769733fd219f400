"""What fur adds to the generic outputs (the fur plugin's output hooks).

- take track `guides` (curves): the guide curves as the rig posed them, every
  recorded frame (`ecs_tentacles.fur.hooks.take_guides`);
- before a recording: the guides posed at the built pose, so take frame 0 has them;
- shard groups: creatures marked `threat` and the creatures with an `emotion` they
  may rouse bake in one shard (the emotion system reads every threat's position);
- take sizes: what the guide curves will hold, from a scene (`guide_sizes`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from ecs_tentacles.fur.checks import guide_count
from ecs_tentacles.fur.hooks import take_guides
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.take.registries import TrackSource
from ecs_tentacles.take.tracks import TakeTrack, TrackSize

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

GUIDES = TakeTrack("guides", "curves", ("guide_points", "guide_widths"), "fur", "guides")
GUIDE_TRACK = TrackSource(GUIDES, take_guides)
POINT_BYTES = 3 * 4 + 4  # a guide point in a frame: position and width (float32)


def guide_sizes(scene: Mapping[str, object]) -> list[TrackSize]:
    """The guide curves of a take of `scene` (defaults filled in): every fur's guides
    (as the groom makes them), each of the points every fur shares (the most a groom
    asks), every frame; once, each guide's owner in the header."""
    creatures = scene["creatures"]
    if not isinstance(creatures, list):
        raise TypeError("a scene's creatures are a list")
    furs = [(i, c) for i, c in enumerate(creatures) if "fur" in c]
    if not furs:
        return []
    guides = [guide_count(c["fur"], c["mantle"])[0] for _, c in furs]
    points = max(c["fur"]["groom"]["points"] for _, c in furs)
    owners = sum(n * (len(str(i)) + 1) for n, (i, _) in zip(guides, furs, strict=True))
    each = f"of {points} points"
    return [TrackSize("fur guides", sum(guides), points * POINT_BYTES, owners, each, chunked=True)]


def pose_fur_at_build(world: Host) -> None:
    """Pose fur guides before the first frame, so a take's frame 0 has them.

    The rig system poses guides during a frame; at the built pose nothing has run. A
    fresh rig (its own dynamics state, thrown away) poses them once; it writes only
    the rig's output buffers, which the real rig rewrites every frame.
    """
    fur = world.get_resource(FurData)
    if world.frame == 0 and fur is not None and len(fur.guides) and "rig" in world.schedule:
        type(world.schedule["rig"])().process(world, 0.0)


def roused(creatures: Sequence[Mapping[str, object]]) -> list[int]:
    """Creatures that must share a shard because one rouses another's emotion.

    A creature marked `threat` rouses any creature with an `emotion` near it (the
    emotion system), wherever their shards are: all of them bake together.
    """
    threats = {i for i, c in enumerate(creatures) if c.get("threat")}
    emotional = {i for i, c in enumerate(creatures) if "emotion" in c}
    if not threats or not (emotional - threats or (len(threats) > 1 and emotional)):
        return []
    return sorted(threats | emotional)
