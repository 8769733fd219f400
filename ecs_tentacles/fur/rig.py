"""The rig's math: every guide's result frame from its bind pose and its control.

Per guide, in the guide's own skin basis (along = the rest direction's tangent part,
side = normal x along, normal), where the rest direction is (cos e0, 0, sin e0)
(thesis 3.2 and 4.3):

1. direction and aim: the rest direction, the *direction* target (the rest direction
   reaching `reach` metres plus the control's offset from its rest position) and the
   *aim* target (root -> control) are blended with weights ``1 - aim - direction``
   (at least 0), `direction`, `aim`, as a normalised weighted sum on the unit sphere;
2. lift: the result turns along the great circle toward the surface normal by the
   fraction `lift` of the angle (lift 1 is the normal, exactly);
3. random twist: it turns about the normal (the follicle axis) by
   ``random * twist_max * multiplier`` (the multiplier fixed per guide at generation).

No flipping: every target is moved into the guide's outer cap (at least its lowest
elevation above the skin; for a bent guide more, so the whole curve stays out) by a
continuous map (`clamp`), and a weighted sum of vectors in a cap stays in it, so a
result can neither enter the surface nor jump when controls move or cross. The frame's
side is the (twisted) rest side made perpendicular to the result; it never degenerates
because the result is never tangent. Frames go to world space with the body's pose and
each guide's rest shape (homogeneous rest-frame coordinates) is posed by them.
Arrays are float32; vectors are (3, n), one row per axis.

Speed (tools/bench_rig.py): `evaluate` is the per-frame entry point, called block by
block with one `control_table` (per-control values and the behaviours in use, once a
frame) and one `RigBuffers` (work buffers kept between frames). With numba installed
(the ``dev`` extra) the kernels of `ecs_tentacles.fur.kernels` do the work, guide by
guide, on all cores for furs of `PARALLEL_GUIDES` guides or more and serially below
(numba's thread pool costs small furs more than it saves and competes with the
physics threads); without it, the whole-array numpy code here (`local_frames`,
`world_frames`, `pose`). ``ECS_TENTACLES_RIG=numpy`` (or `BACKEND = "numpy"`) forces
numpy. Both give the same results within float32 rounding; a behaviour that no
control uses is skipped by both.
"""

from __future__ import annotations

import contextlib
import os
import threading
from contextlib import AbstractContextManager
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from ecs_tentacles.fur.scratch import RigBuffers
from ecs_tentacles.fur.vectors import TINY
from ecs_tentacles.numeric.optional_kernels import OptionalKernels

F32 = np.float32


# the per-guide (n,) arrays of a `Bind`
PER_GUIDE = ("rest_cos", "rest_sin", "tan_min", "multiplier", "control", "body")


@dataclass
class Bind:
    """The rig's bind pose of n guides (float32, body-local, vectors as (3, n)).

    Guides are best ordered by control (the builder does it): per-control values then
    reach the guides through a few runs (`np.repeat`) instead of a gather per guide.
    Arrays are made contiguous float32 (int64 indices) on construction.
    """

    root: np.ndarray
    basis: np.ndarray  # (3, 3, n): along (rest direction's unit tangent), side, normal
    rest_cos: np.ndarray  # (n,) cos and sin of the rest direction's elevation
    rest_sin: np.ndarray
    tan_min: np.ndarray  # (n,) tan of the lowest elevation allowed
    multiplier: np.ndarray  # (n,)
    control: np.ndarray  # (n,) control row
    body: np.ndarray  # (n,) index into the bodies passed to `world_frames`
    shape_h: np.ndarray  # (n, points, 4): rest-frame coordinates and a 1

    def __post_init__(self) -> None:
        for name in ("root", "basis", "rest_cos", "rest_sin", "tan_min", "multiplier", "shape_h"):
            setattr(self, name, np.ascontiguousarray(getattr(self, name), dtype=F32))
        self.control = np.ascontiguousarray(self.control, dtype=np.int64)
        self.body = np.ascontiguousarray(self.body, dtype=np.int64)
        starts = np.flatnonzero(np.diff(self.control)) + 1
        starts = np.concatenate([[0], starts]) if len(self.control) else starts
        self.run_control = self.control[starts]
        self.run_length = np.diff(np.append(starts, len(self.control)))
        # the kernels index without checks: `evaluate` compares these with its tables
        self.controls_needed = int(self.control.max()) + 1 if len(self.control) else 0
        self.bodies_needed = int(self.body.max()) + 1 if len(self.body) else 0
        lone = len(self.body) and self.body.min() == self.body.max()
        self.one_body: int | None = int(self.body[0]) if lone else None

    def __len__(self) -> int:
        return len(self.control)

    def part(self, rows: slice | np.ndarray) -> Bind:
        """The guides `rows` (a slice, indices or a mask), as contiguous copies (blocks
        that stay in cache)."""
        parts = {k: np.ascontiguousarray(getattr(self, k)[rows]) for k in PER_GUIDE}
        return Bind(
            root=np.ascontiguousarray(self.root[:, rows]),
            basis=np.ascontiguousarray(self.basis[:, :, rows]),
            shape_h=self.shape_h[rows],
            **parts,
        )

    def spread(self, table: np.ndarray) -> np.ndarray:
        """Per-control rows (k, n_controls) -> per-guide rows (k, n), run by run."""
        return np.repeat(table[:, self.run_control], self.run_length, axis=1)

    @property
    def along(self) -> np.ndarray:
        """Unit tangents (3, n) of the rest directions."""
        result: np.ndarray = self.basis[0]
        return result

    @property
    def side(self) -> np.ndarray:
        """Unit side vectors (3, n): normal x along."""
        result: np.ndarray = self.basis[1]
        return result

    @property
    def normal(self) -> np.ndarray:
        """Unit surface normals (3, n) at the roots."""
        result: np.ndarray = self.basis[2]
        return result

    @property
    def rest(self) -> np.ndarray:
        """Rest directions (3, n), body-local."""
        result: np.ndarray = self.rest_cos * self.along + self.rest_sin * self.normal
        return result


@dataclass
class ControlValues:
    """Effective per-control values (float32): weights, twist angle, targets (3, n_controls)."""

    lift: np.ndarray
    aim: np.ndarray
    direction: np.ndarray
    twist: np.ndarray  # radians for a multiplier of 1
    position: np.ndarray  # creature frame
    offset: np.ndarray  # (position - rest position) / reach

    def table(self) -> np.ndarray:
        """All values as rows (10, n_controls): lift, aim, direction, twist, position, offset."""
        rows = [self.lift, self.aim, self.direction, self.twist, *self.position, *self.offset]
        return np.array(rows, dtype=F32).reshape(10, -1)


# rows of the per-control table (`control_table`)
UNLIFT, KEEP, TWIST, TARGETS, WEIGHTS = 0, 1, 2, slice(3, 9), slice(9, 11)
TABLE_ROWS = 11


@dataclass
class Plan:
    """What one frame's controls ask of the rig: their table and which behaviours act."""

    values: ControlValues
    table: np.ndarray  # (TABLE_ROWS, n_controls) float32, the kernels' input
    lifting: bool
    aiming: bool
    directing: bool
    twisting: bool


def control_table(values: ControlValues) -> Plan:
    """Per-control rows, computed once a frame, that the kernels read for each guide.

    Rows: 1 - lift, the rest direction's weight ``max(1 - aim - direction, 0)``, the
    twist angle, the aim and direction targets interleaved (x_aim, x_dir, y_aim,
    y_dir, z_aim, z_dir: position and offset) and their weights (aim, direction).
    A behaviour whose values are all zero is skipped (the numpy path leaves out its
    work, the kernels its trigonometry; their terms then add exact zeros), so the
    cost follows what the controls use.
    """
    table = np.empty((TABLE_ROWS, len(values.lift)), dtype=F32)
    table[UNLIFT] = F32(1.0) - values.lift
    np.maximum(F32(1.0) - values.aim - values.direction, F32(0.0), out=table[KEEP])
    table[TWIST] = values.twist
    targets = table[TARGETS].reshape(3, 2, -1)
    targets[:, 0] = values.position
    targets[:, 1] = values.offset
    table[WEIGHTS] = values.aim, values.direction
    return Plan(
        values,
        table,
        lifting=bool(values.lift.any()),
        aiming=bool(values.aim.any()),
        directing=bool(values.direction.any()),
        twisting=bool(values.twist.any()),
    )


Coords = tuple[np.ndarray, np.ndarray, np.ndarray]


def _unit(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> Coords:
    inv = 1.0 / np.maximum(np.sqrt(x * x + y * y + z * z), TINY)
    return x * inv, y * inv, z * inv


def _clamp(x: np.ndarray, y: np.ndarray, z: np.ndarray, tan_min: np.ndarray) -> Coords:
    """`clamp_to_cap` in skin coordinates, for unit (x, y, z)."""
    return _unit(x, y, np.maximum(z, tan_min))


def _to_skin(bind: Bind, v: np.ndarray) -> np.ndarray:
    """Body-local vectors (3, n) in each guide's skin basis: rows along, side, normal."""
    skin: np.ndarray = np.einsum("in,jin->jn", v, bind.basis)
    return skin


def skin_directions(bind: Bind, values: ControlValues) -> tuple[Coords, Coords | None]:
    """Result direction and side of every guide in skin coordinates (None: the rest side)."""
    per_guide = bind.spread(values.table())
    lift, aim, turn, twist = per_guide[0], per_guide[1], per_guide[2], per_guide[3]
    x, z = bind.rest_cos, bind.rest_sin
    y: np.ndarray | float = 0.0
    aiming, directing = values.aim.any(), values.direction.any()
    if aiming or directing:
        keep = np.maximum(1.0 - aim - turn, 0.0)
        x, y, z = keep * x, 0.0, keep * z
        if directing:
            ox, oy, oz = _to_skin(bind, per_guide[7:10])
            ox, oy, oz = _clamp(*_unit(ox + bind.rest_cos, oy, oz + bind.rest_sin), bind.tan_min)
            x, y, z = x + turn * ox, turn * oy, z + turn * oz
        if aiming:
            ax, ay, az = _clamp(*_unit(*_to_skin(bind, per_guide[4:7] - bind.root)), bind.tan_min)
            x, y, z = x + aim * ax, y + aim * ay, z + aim * az
        if not values.lift.any():
            x, y, z = _unit(x, y, z)  # type: ignore[arg-type]
    if values.lift.any():
        # turn toward the normal along the great circle: the polar angle shrinks by `lift`
        # (this also normalises a blend: the angle and the azimuth do not need unit input)
        flat = np.sqrt(x * x + y * y)
        polar = (1.0 - lift) * np.arctan2(flat, z)
        scale = np.sin(polar) / np.maximum(flat, TINY)
        x, y, z = x * scale, y * scale, np.cos(polar)
    if not values.twist.any():
        if isinstance(y, float):
            return (x, np.zeros_like(x), z), None  # still in the rest plane: rest side holds
        side_x: np.ndarray | float = 0.0
        side_y: np.ndarray | float = 1.0
    else:
        angle = twist * bind.multiplier
        cos, sin = np.cos(angle), np.sin(angle)
        x, y = x * cos - y * sin, x * sin + y * cos
        side_x, side_y = -sin, cos
    # the twisted rest side, made perpendicular to the result; both are unit vectors, so
    # its length is sqrt(1 - k^2) >= sin(lowest elevation) > 0
    k = side_x * x + side_y * y
    inv = 1.0 / np.sqrt(np.maximum(1.0 - k * k, TINY))
    side = ((side_x - k * x) * inv, (side_y - k * y) * inv, -k * z * inv)
    return (x, np.asarray(y), z), side


# "auto": the numba kernels when numba imports, else numpy; "numpy": numpy always.
BACKEND = os.environ.get("ECS_TENTACLES_RIG", "auto")
_KERNELS = OptionalKernels("ecs_tentacles.fur.kernels")


def kernels() -> ModuleType | None:
    """The numba kernels (`ecs_tentacles.fur.kernels`), or None: numpy does the work."""
    return None if BACKEND == "numpy" else _KERNELS.get()


PARALLEL_GUIDES = 20_000  # below, serial kernels were as fast (tools/bench_rig.py, 2 cores)


def use_parallel(guides: int) -> bool:
    """Whether a fur of `guides` guides runs the parallel kernels."""
    return guides >= PARALLEL_GUIDES


_KERNEL_LOCK = threading.Lock()  # numba's pool is not documented as safe to share


def kernel(k: ModuleType, name: str, parallel: bool) -> tuple[Any, AbstractContextManager[Any]]:
    """Kernel `name` of `k` for all cores or serial, and the lock a call takes (parallel)."""
    lock = _KERNEL_LOCK if parallel else contextlib.nullcontext()
    return getattr(k, name if parallel else f"{name}_serial"), lock


NO_LOCAL = np.empty((4, 3, 0), dtype=F32)
NO_WORLD = np.empty((0, 4, 3), dtype=F32)
NO_CURVES = np.empty((0, 1, 3), dtype=F32)


def _kernel_frames(
    k: ModuleType,
    bind: Bind,
    plan: Plan,
    s: RigBuffers,
    rotation: np.ndarray,
    position: np.ndarray,
    local: np.ndarray,
    world: np.ndarray,
    curves: np.ndarray,
    parallel: bool,
) -> None:
    """The numba passes (blend, whole-array trigonometry, frames): see `kernels`."""
    blend, lock = kernel(k, "blend", parallel)
    with lock:
        s.use(len(bind))
        axis, flat, unlift, angle = s("k_axis", 3), s("k_flat"), s("k_unlift"), s("k_angle")
        normalise = (plan.aiming or plan.directing) and not plan.lifting
        blend(
            bind.control, plan.table, bind.rest_cos, bind.rest_sin, bind.tan_min, bind.multiplier,
            bind.basis, bind.root, normalise, axis, flat, unlift, angle,
        )  # fmt: skip
        polar_sin, polar_cos = s("k_polar_sin"), s("k_polar_cos")
        twist_cos, twist_sin = s("k_twist_cos"), s("k_twist_sin")
        if plan.lifting:
            polar = s("k_polar")
            np.arctan2(flat, axis[2], out=polar)
            polar *= unlift
            np.sin(polar, out=polar_sin)
            np.cos(polar, out=polar_cos)
        if plan.twisting:
            np.cos(angle, out=twist_cos)
            np.sin(angle, out=twist_sin)
        kernel(k, "frames", parallel)[0](
            axis, flat, polar_sin, polar_cos, twist_cos, twist_sin, plan.lifting,
            plan.twisting, bind.basis, bind.root, bind.body, rotation, position, local, world,
            bind.shape_h, curves,
        )  # fmt: skip


def evaluate(
    bind: Bind,
    values: ControlValues | Plan,
    rotation: np.ndarray,
    position: np.ndarray,
    frames: np.ndarray,
    curves: np.ndarray,
    scratch: RigBuffers | None = None,
    parallel: bool | None = None,
) -> None:
    """World frames (n, 4, 3) and posed curves (n, points, 3) of every guide, in place.

    `local_frames`, `world_frames` and `pose` in one call, by the numba kernels when
    they are there. `rotation` (n_bodies, 3, 3) and `position` (n_bodies, 3) are the
    bodies' poses. `parallel`: the kernels for all cores (default: for a block of
    `PARALLEL_GUIDES` or more; callers going block by block pass the whole fur's).
    """
    s = RigBuffers() if scratch is None else scratch
    plan = values if isinstance(values, Plan) else control_table(values)
    if bind.controls_needed > plan.table.shape[1] or bind.bodies_needed > len(rotation):
        raise IndexError("a guide names a control or a body that the values do not have")
    k = kernels()
    if k is None:
        local = local_frames(bind, plan, out=s.use(len(bind))("local", 4, 3), scratch=s)
        world_frames(bind, local, rotation, position, out=frames, scratch=s)
        np.matmul(bind.shape_h, frames, out=curves)
        return
    turn = np.ascontiguousarray(rotation, dtype=F32)
    move = np.ascontiguousarray(position, dtype=F32)
    many = use_parallel(len(bind)) if parallel is None else parallel
    _kernel_frames(k, bind, plan, s, turn, move, NO_LOCAL, frames, curves, many)


def local_frames(
    bind: Bind,
    values: ControlValues | Plan,
    out: np.ndarray | None = None,
    scratch: RigBuffers | None = None,
) -> np.ndarray:
    """Body-local frames (4, 3, n): result axis, up (axis x side), side, and the root.

    Give a `Plan` (`control_table(values)`) to share it between blocks of guides and a
    `RigBuffers` kept between frames for the kernels' work buffers.
    """
    n = len(bind)
    out = np.empty((4, 3, n), dtype=F32) if out is None else out
    s = RigBuffers() if scratch is None else scratch
    plan = values if isinstance(values, Plan) else control_table(values)
    k = kernels()
    if k is not None:
        if bind.controls_needed > plan.table.shape[1]:
            raise IndexError("a guide names a control that the values do not have")
        one = np.eye(3, dtype=F32)[None]
        origin = np.zeros((1, 3), F32)
        many = use_parallel(n)
        _kernel_frames(k, bind, plan, s, one, origin, out, NO_WORLD, NO_CURVES, many)
        return out
    (x, y, z), side = skin_directions(bind, plan.values)
    along, normal = bind.along, bind.normal
    if side is None:  # axis in the rest plane, side unchanged: up = (-z, 0, x)
        np.multiply(x, along, out=out[0])
        out[0] += z * normal
        np.multiply(x, normal, out=out[1])
        out[1] -= z * along
        out[2] = bind.side
    else:
        sx, sy, sz = side
        skin = np.array([[x, y, z], [y * sz - z * sy, z * sx - x * sz, x * sy - y * sx], side])
        np.einsum("kjn,jin->kin", skin, bind.basis, out=out[:3])
    out[3] = bind.root
    return out


def world_frames(
    bind: Bind,
    local: np.ndarray,
    rotation: np.ndarray,
    position: np.ndarray,
    out: np.ndarray,
    scratch: RigBuffers | None = None,
) -> np.ndarray:
    """Frames (4, 3, n) to world space, written into `out` (n, 4, 3) for `pose`.

    `rotation` (n_bodies, 3, 3) and `position` (n_bodies, 3) are the bodies' poses;
    `bind.body` picks each guide's.
    """
    n = local.shape[2]
    body = bind.one_body if len(rotation) > 1 else 0
    if body is not None:  # one body: four small matrix products for all, then one copy
        turned = np.empty_like(local) if scratch is None else scratch.use(n)("world", 4, 3)
        np.matmul(rotation[body].astype(F32), local, out=turned)
        turned[3] += position[body].astype(F32)[:, None]
        out.reshape(n, 12)[...] = turned.reshape(12, n).T  # numpy copies this fast
        return out
    rows = np.ascontiguousarray(local.transpose(2, 0, 1))  # (n, 4, 3)
    turn = rotation.astype(F32).transpose(0, 2, 1)[bind.body]  # (n, 3, 3), transposed
    np.matmul(rows, turn, out=out)
    out[:, 3] += position.astype(F32)[bind.body]
    return out


def pose(shape_h: np.ndarray, frames: np.ndarray, out: np.ndarray) -> np.ndarray:
    """World points (n, points, 3) = rest-frame coordinates x world frame, batched."""
    k = kernels()
    if k is None:
        return np.matmul(shape_h, frames, out=out)
    run, lock = kernel(k, "pose", use_parallel(len(shape_h)))
    with lock:
        run(shape_h, frames, out)
    return out
