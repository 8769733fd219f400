"""Binding: the fur stores packed into the rig's float32 arrays, once per change.

`make_bind` builds the `rig.Bind` of every guide (rest directions lifted into each
guide's cap, bodies indexed), `control_values` turns the control store into the
effective per-control values the rig reads each frame, `make_strands` the dynamic
state of guides whose fur has the dynamic behaviour, and `ControlTracks` writes
keyframed tracks into the control store.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import numpy as np

from ecs_tentacles.fur.dynamics import Strands, blend_profile
from ecs_tentacles.fur.rig import F32, TABLE_ROWS, Bind, ControlValues, Plan, control_table, kernels
from ecs_tentacles.fur.stores import BEHAVIOURS, COLUMNS, ControlStore, FurData
from ecs_tentacles.fur.vectors import clamp_to_cap, cross, dot, normalize
from ecs_tentacles.numeric.keyframes import TrackSet
from ecs_tentacles.numeric.optional_kernels import OptionalKernels

MAX_ELEVATION = np.radians(80.0)  # the cap never shrinks to nothing, even for bent guides
LIFT, AIM, DIRECTION, RANDOM, DYNAMIC = range(5)


def cone_angles(shape: np.ndarray) -> np.ndarray:
    """Per guide, the widest angle between its axis and a chord from the root (radians)."""
    chord = shape[:, 1:]
    off_axis = np.sqrt(chord[..., 1] ** 2 + chord[..., 2] ** 2)
    angles = np.arctan2(off_axis, np.maximum(chord[..., 0], 0.0) + (off_axis == 0))
    return np.asarray(angles.max(axis=1) if chord.shape[1] else np.zeros(len(shape)))


def make_bind(fur: FurData, rows: slice = slice(None)) -> tuple[Bind, np.ndarray]:
    """The rig's bind pose of the guides `rows` (default every guide), and the Transform
    rows of their bodies (sorted; `Bind.body` indexes them). Each guide's bind depends
    on that guide alone, so binding a creature's guides gives what binding all gives."""
    g = fur.guides
    body_row, fur_row = g.body_row[rows], g.fur_row[rows]
    shape = fur.shape[rows]
    bodies, body_index = np.unique(body_row, return_inverse=True)
    floor = fur.sets.min_elevation[fur_row] + cone_angles(shape)
    tan_min = np.tan(np.minimum(floor, MAX_ELEVATION)).astype(F32)
    normal = normalize(g.normal[rows].T.astype(F32))
    rest = clamp_to_cap(normalize(g.rest[rows].T.astype(F32)), normal, tan_min)
    rest_sin = dot(rest, normal)
    along = rest - rest_sin * normal
    upright = dot(along, along) < 1e-12  # a guide standing on its normal: its side decides
    along[:, upright] = cross(g.side[rows].T.astype(F32)[:, upright], normal[:, upright])
    along = normalize(along)
    shape_h = np.ones((len(shape), fur.points, 4), dtype=F32)
    shape_h[..., :3] = shape
    bind = Bind(
        root=np.ascontiguousarray(g.root[rows].T, dtype=F32),
        basis=np.stack([along, cross(normal, along), normal]),
        rest_cos=np.sqrt(np.maximum(1.0 - rest_sin * rest_sin, 0.0)),
        rest_sin=rest_sin,
        tan_min=tan_min,
        multiplier=g.multiplier[rows].astype(F32),
        control=g.control_row[rows].copy(),
        body=body_index.astype(np.int64),
        shape_h=shape_h,
    )
    return bind, bodies


def _unit_interval(x: np.ndarray) -> np.ndarray:
    """x clipped to [0, 1] (np.clip's overhead is large for a few controls each frame);
    NaN stays NaN and -0.0 becomes 0.0 (np.maximum's zero sign depends on the CPU)."""
    clipped: np.ndarray = np.minimum(np.maximum(x, 0.0), 1.0) + 0.0
    return clipped


def control_values(fur: FurData) -> tuple[ControlValues, np.ndarray]:
    """Effective values of every control (behaviours a fur lacks are 0) and `dynamic`."""
    c, sets = fur.controls, fur.sets
    on = sets.enabled[c.fur_row]
    lift = _unit_interval(c.lift + c.drive_lift) * on[:, LIFT]
    random = _unit_interval(c.random + c.drive_random) * on[:, RANDOM]
    offset = (c.position - c.rest_position) / sets.reach[c.fur_row][:, None]
    values = ControlValues(
        lift=lift.astype(F32),
        aim=(_unit_interval(c.aim) * on[:, AIM]).astype(F32),
        direction=(_unit_interval(c.direction) * on[:, DIRECTION]).astype(F32),
        twist=(random * sets.twist_max[c.fur_row]).astype(F32),
        position=np.ascontiguousarray(c.position.T, dtype=F32),
        offset=np.ascontiguousarray(offset.T, dtype=F32),
    )
    return values, (_unit_interval(c.dynamic) * on[:, DYNAMIC]).astype(F32)


def control_plan(fur: FurData) -> tuple[Plan, np.ndarray]:
    """`control_table(control_values(fur))` and `dynamic`: the frame's control values,
    their table and which behaviours act (one numba kernel when the rig's kernels run:
    the same numbers)."""
    fast = control_kernels()
    if fast is None:
        values, dynamic = control_values(fur)
        return control_table(values), dynamic
    c, sets = fur.controls, fur.sets
    n = len(c)
    values = ControlValues(
        lift=np.empty(n, F32),
        aim=np.empty(n, F32),
        direction=np.empty(n, F32),
        twist=np.empty(n, F32),
        position=np.empty((3, n), F32),
        offset=np.empty((3, n), F32),
    )
    dynamic, table = np.empty(n, F32), np.empty((TABLE_ROWS, n), F32)
    flags = fast.control_plan(
        c.fur_row, c.position, c.rest_position, c.lift, c.drive_lift, c.aim, c.direction,
        c.random, c.drive_random, c.dynamic, sets.enabled, sets.twist_max, sets.reach,
        values.lift, values.aim, values.direction, values.twist, values.position,
        values.offset, dynamic, table,
    )  # fmt: skip
    lifting, aiming, directing, twisting = (bool(flag) for flag in flags)
    return Plan(values, table, lifting, aiming, directing, twisting), dynamic


_CONTROL_KERNELS = OptionalKernels("ecs_tentacles.fur.control_kernels")


def control_kernels() -> ModuleType | None:
    """`control_plan`'s kernel, or None: numpy does the work (no numba, or
    ``ECS_TENTACLES_RIG=numpy``)."""
    return None if kernels() is None else _CONTROL_KERNELS.get()


def make_strands(fur: FurData, gravity: np.ndarray, dt: float) -> Strands | None:
    """Strand state for the guides of furs with the dynamic behaviour (None if none)."""
    g, sets = fur.guides, fur.sets
    rows = np.flatnonzero(sets.enabled[g.fur_row, DYNAMIC] > 0)
    if not len(rows):
        return None
    f = g.fur_row[rows]
    steps = np.linalg.norm(np.diff(fur.shape[rows], axis=1), axis=2)
    segment = np.concatenate([np.zeros((len(rows), 1)), steps], axis=1).T
    return Strands(
        guides=rows,
        segment=np.ascontiguousarray(segment, dtype=F32),  # the kernel reads rows
        pull=(1.0 - np.exp(-sets.stiffness[f] * dt)).astype(F32),
        keep=np.exp(-sets.damping[f] * dt).astype(F32),
        gravity=(np.outer(gravity, sets.gravity_scale[f]) * dt * dt).astype(F32),
        profile=blend_profile(fur.points)[:, None, None],
    )


@dataclass
class ControlTracks:
    """Keyframed control attributes, written into the ControlStore at a time."""

    tracks: TrackSet

    def apply(self, controls: ControlStore, t: float) -> None:
        """Write every track's value at time `t` into its control's attribute."""
        if not len(self.tracks):
            return
        values = self.tracks.evaluate(t)
        rows, columns = self.tracks.rows, self.tracks.columns
        moved = columns < 3
        if moved.any():
            controls.position[rows[moved], columns[moved]] = values[moved]
        for name in BEHAVIOURS:
            mask = columns == COLUMNS[name][0]
            if mask.any():
                getattr(controls, name)[rows[mask]] = values[mask]
