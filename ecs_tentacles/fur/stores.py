"""Struct-of-array stores of the fur rig: guides, controls, furs, emotions.

`FurData` (``world.resource(FurData)``) holds them. Rows go when their creature is
despawned. Guides of all creatures share one point count (`FurData.points`): the first
fur built sets it and guides of later furs with another count are resampled along their
length.

Anything that changes the bind pose (roots, normals, rest directions, shapes,
multipliers, control assignment) must call `FurData.touch()` so the rig re-binds;
the `FurGuide` component does that on every write. (Creatures coming and going bump
`version` alone: the rig then binds or cuts out just their guides.)

The rig's outputs (`FurData.curves`, `FurData.frames`) may be evaluated when first read
rather than in the rig's slot of the frame: the rig hands `defer` the evaluation with
its inputs of that slot (controls, body poses, bind), and reading either output, or a
change of the guide rows (a spawn's shapes, a despawn), runs it first. What is read is
the same either way; a frame whose fur nobody reads does not evaluate it. (`reads`
counts the reads: while they come every frame, as a recorder's or a renderer's do,
the rig evaluates in its slot.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ecs_tentacles.numeric.keyframes import Channel
from ecs_tentacles.store import ArrayStore, Field, without_rows

# The rig's behaviours, in order: a fur switches each on or off (`FurSetStore.enabled`),
# and a control drives each through its ControlStore field of the same name.
BEHAVIOURS = ("lift", "aim", "direction", "random", "dynamic")
# Track columns of the ControlStore: position x, y, z, then the behaviour values.
COLUMNS = {"position": (0, 1, 2)} | {name: (3 + i,) for i, name in enumerate(BEHAVIOURS)}


class GuideStore(ArrayStore):
    """Per guide, in the mantle body's local frame: root, normal, rest frame and links.

    `rest` is the unit direction of the curve's first segment (the guide's axis runs
    down the curve from its root); `side` is the rest frame's sideways unit vector
    (normal x rest, normalised). Shapes are in `FurData.shape` (rest-frame coordinates).
    """

    entity = Field(dtype=np.int64)
    body_row = Field(dtype=np.int64, refers="transforms")  # Transform row of the mantle
    fur_row = Field(dtype=np.int64, refers="fur.sets")
    control_row = Field(dtype=np.int64, refers="fur.controls")
    root = Field((3,))
    normal = Field((3,), default=(0.0, 0.0, 1.0))
    rest = Field((3,), default=(1.0, 0.0, 0.0))
    side = Field((3,), default=(0.0, 1.0, 0.0))
    length = Field()
    multiplier = Field()  # random-twist multiplier in [-1, 1], fixed at generation


class ControlStore(ArrayStore):
    """Per control: position in the creature frame, rest position and behaviour values.

    `lift` ... `dynamic` are the values the scene, tracks and scripts set (0..1);
    `drive_lift` / `drive_random` are what the emotion system adds on top.
    """

    entity = Field(dtype=np.int64)
    fur_row = Field(dtype=np.int64, refers="fur.sets")
    emotion_row = Field(dtype=np.int64, default=-1, refers="fur.emotions")
    position = Field((3,))
    rest_position = Field((3,))
    lift = Field()
    aim = Field()
    direction = Field()
    random = Field()
    dynamic = Field()
    emotion = Field(default=1.0)  # how much the creature's emotion drives this control
    drive_lift = Field()
    drive_random = Field()
    colour = Field((3,), default=(1.0, 0.8, 0.0))
    size = Field(default=0.03)


class FurSetStore(ArrayStore):
    """Per creature with fur: which behaviours it has and the rig's constants."""

    creature = Field(dtype=np.int64)
    body_row = Field(dtype=np.int64, refers="transforms")
    enabled = Field((len(BEHAVIOURS),), default=1.0)  # 1 on / 0 off, in BEHAVIOURS order
    twist_max = Field()  # radians of twist at random = 1 for multiplier 1
    reach = Field(default=0.1)  # metres: direction target distance along the guide
    min_elevation = Field()  # radians above the skin every guide stays
    stiffness = Field(default=8.0)  # 1/s: how fast a dynamic strand returns to the rig
    damping = Field(default=2.0)  # 1/s: velocity lost by a dynamic strand
    gravity_scale = Field(default=1.0)
    erect_lift = Field(default=1.0)  # emotion level 1 adds this much lift
    erect_random = Field()  # and this much random
    colour = Field((3,))
    width = Field(default=0.002)
    children = Field(dtype=np.int64)


class EmotionStore(ArrayStore):
    """Per creature with an emotion: sensing, timing and the current level."""

    creature = Field(dtype=np.int64)
    body_row = Field(dtype=np.int64, refers="transforms")
    radius = Field(default=1.0)
    rise = Field(default=0.4)  # seconds to 90 % of a rise
    decay = Field(default=2.0)  # seconds to 90 % of a decay
    anticipation = Field(default=0.3)
    state = Field()  # the critically damped follower's position
    speed = Field()  # and its velocity
    level = Field()  # state - anticipation * speed / omega, in [-1, 1]
    threatened = Field(dtype=np.bool_, default=False)


class FurData:
    """The fur stores of one world (``world.resource(FurData)``), plus the rig's output buffers.

    After the rig runs: `points` (n_guides, points, 3) world polylines (float32) and
    `frames` (n_guides, 4, 3): rows are the guide's axis, up and side unit vectors and
    its root, in world space.
    """

    provided_by = "fur"  # the plugin that makes it (named by `world.resource` errors)

    def __init__(self) -> None:
        self.guides = GuideStore()
        self.controls = ControlStore()
        self.sets = FurSetStore()
        self.emotions = EmotionStore()
        self.points = 0  # points per guide; set by the first fur built
        self._rows = 0  # guides whose shapes are joined: the buffers' live rows
        self._shape = np.zeros((0, 0, 3))  # buffers with room to grow (doubling)
        self._curves = np.zeros((0, 0, 3), dtype=np.float32)
        self._frames = np.zeros((0, 4, 3), dtype=np.float32)
        self._added: list[tuple[int, np.ndarray]] = []  # (guides then, shapes) not yet joined
        self.version = 0  # bumped by any change of the bind pose ...
        self.touches = 0  # ... and this too when not by a creature coming or going
        self.tracks: list[Channel] = []  # control attributes (columns: COLUMNS)
        self._pending: Callable[[], None] | None = None  # the rig's evaluation, run when read
        self.reads = 0  # times `curves` or `frames` was read (the rig defers while none come)

    @property
    def shape(self) -> np.ndarray:
        """Per guide: its points in its rest frame (axis, up, side); (n_guides, points, 3)."""
        self._join()
        return self._shape[: self._rows]

    @property
    def curves(self) -> np.ndarray:
        """World polylines (n_guides, points, 3) as the rig last posed them."""
        self.reads += 1
        self.settle()
        self._join()
        return self._curves[: self._rows]

    @property
    def frames(self) -> np.ndarray:
        """World frames (n_guides, 4, 3): axis, up, side and root, as the rig last posed them."""
        self.reads += 1
        self.settle()
        self._join()
        return self._frames[: self._rows]

    def outputs(self) -> tuple[np.ndarray, np.ndarray]:
        """(frames, curves) as they are, without running a deferred evaluation (the rig
        writes them through this)."""
        self._join()
        return self._frames[: self._rows], self._curves[: self._rows]

    def defer(self, evaluation: Callable[[], None]) -> None:
        """The rig's evaluation of this frame, writing `outputs()`: run when the outputs
        are next read (`settle`), replacing any earlier one not run yet."""
        self._pending = evaluation

    def settle(self) -> None:
        """Run the deferred evaluation, if any (reading `curves` or `frames` does)."""
        pending, self._pending = self._pending, None
        if pending is not None:
            pending()

    def discard(self) -> None:
        """Forget the deferred evaluation: every output row is about to be written anew."""
        self._pending = None

    def add_shapes(self, shapes: np.ndarray) -> None:
        """Append rest shapes (k, points, 3) for guides just added; grow the buffers.

        The shapes are joined when next read (the new guides' outputs zeroed), so a
        crowd whose creatures each add a few guides is joined once; the buffers grow by
        doubling, so a creature spawned into a big furred crowd copies no one else's.
        """
        self.settle()  # the rows it writes are the rows known now
        self._added.append((len(self.guides), shapes))
        self.version += 1

    def _join(self) -> None:
        if not self._added:
            return
        for n, shapes in self._added:
            keep = n - len(shapes)  # the guides before these (all of them, when built in turn)
            if keep > self._rows:
                raise ValueError(f"fur shapes for guides {keep}..{n}, but only {self._rows} known")
            self._rows = keep
            self._reserve(n)
            self._shape[keep:n] = shapes
            self._curves[keep:n] = 0.0
            self._frames[keep:n] = 0.0
            self._rows = n
        self._added.clear()

    def _reserve(self, rows: int) -> None:
        """Room for `rows` guides of `points` points in the buffers (the live rows kept)."""
        room = len(self._shape)
        if rows <= room and self._shape.shape[1] == self.points:
            return
        room = rows if not self._rows else max(rows, 2 * room)
        live = self._rows
        for name, dtype, tail in (
            ("_shape", np.float64, (self.points, 3)),
            ("_curves", np.float32, (self.points, 3)),
            ("_frames", np.float32, (4, 3)),
        ):
            grown = np.zeros((room, *tail), dtype=dtype)
            if live:
                grown[:live] = getattr(self, name)[:live]
            setattr(self, name, grown)

    def drop(self, moved: dict[str, np.ndarray]) -> None:
        """A despawn took rows out of the stores (`moved`: old row -> new row, -1
        removed, by store name): the guides' shapes and outputs and the control tracks
        follow; the rig re-binds if fur went with it."""
        guides = moved.get("fur.guides")
        if guides is not None:
            self.settle()  # into the rows as they were
            self._join()
            rows = self._rows
            for buffer in (self._shape, self._curves, self._frames):
                without_rows(buffer[:rows], guides)  # in place: the buffers keep their room
            self._rows = rows - int(np.count_nonzero(guides < 0))
        controls = moved.get("fur.controls")
        if controls is not None:
            self.tracks = [
                replace(channel, row=int(controls[channel.row]))
                for channel in self.tracks
                if controls[channel.row] >= 0
            ]
        if any(name.startswith("fur.") for name in moved):
            self.version += 1  # (a creature without fur leaves the bind pose alone)

    def touch(self) -> None:
        """Mark the bind pose as changed (after writing guide arrays directly)."""
        self.version += 1
        self.touches += 1
