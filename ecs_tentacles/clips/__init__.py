"""Gait clips, the kinematic tier of crowds' level of detail: cheaper stand-ins for
creatures far from the action (plugin `clips`, which scenes turned on or off as `lod`
before and still may, with a warning; the tiers' rules are the physics',
`ecs_tentacles.physics.lod`, scene key `physics.lod`).

`clips` (gait clips: one morphology's crawl and idle loops recorded with the full
physics, replayed for many creatures at once with no dynamics, and the joint state that
promotes a replayed creature back to the full physics without a jump), `gait_world` (the
one-creature recording world), `frames` (ground-frame math), `cache` (clips shared by
morphology). Imports the core and the physics; never the renderer or the CLI.
"""

from ecs_tentacles.clips.cache import ClipCache, morphology_key
from ecs_tentacles.clips.clips import CRAWL, IDLE, Clip, GaitClips

__all__ = ["CRAWL", "IDLE", "Clip", "ClipCache", "GaitClips", "morphology_key"]
