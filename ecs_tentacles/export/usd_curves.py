"""A take's curves tracks (the fur guides) on a USD stage, chunk of frames by chunk.

    curves = CurvesTrack(pxr, layer, header, track, mantles)   # a BasisCurves per owner
    for first, chunk in source.chunks():
        curves.add(first, chunk, roots)

Each owner's curves are one `BasisCurves` (linear, `<c>/<c>_<folder>/<c>_<item>`), their
points, widths and extent sampled; curves no creature owns sit at `/World/<folder>/`.

World space (the rigid form: `mantles` None): the take's points every frame.

Carried (the skinned form): a creature's folder Xform (`<c>_fur`) follows its mantle
(the mantle's pose in the creature's moving root frame, `RootFrames`: orient sampled,
translate (float3) written where it moves, which with the SkelRoot at the mantle is
once), and the points are in the mantle's frame. Guides that ride the mantle
without swaying (a replayed creature's) then keep their points frame after frame, and
a sample is written only where they move: `Held` keeps a value once it is more than
half of `TOLERANCE` (0.25 mm) from the one last written (and the frame before it, so
USD's linear interpolation between written samples stays within `TOLERANCE`). Widths
and extents are held the same way (exactly). A take stores guide points in steps of
0.1 mm, so in its mantle's frame a stiff guide (the hedgehog and bird presets) jitters
by up to 0.12 mm from frame to frame, while a cat's sways by a centimetre: the limit
sits between them. In the 30 s 1,024 crowd half the fur guides stayed within 3 um of
their first pose in their mantle's frame (before the take's rounding) while one in ten
swayed by 1.6 cm or more.

Reads the chunks it is handed; writes prims and time samples through the layer.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.export.names import FOLDERS, unique_path
from ecs_tentacles.export.root_frames import RootFrames
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.take import Take, TakeTrack

if TYPE_CHECKING:
    from pxr import Sdf, UsdGeom

TOLERANCE = 5e-4  # m: a carried curve point is within this of the take's at every frame


class Held:
    """Samples of one attribute written only where its value moves: more than `limit`
    from the last written one; the frame before such a move is written too."""

    def __init__(self, limit: float) -> None:
        self.limit = limit
        self.written: np.ndarray | None = None
        self.skipped: tuple[int, np.ndarray] | None = None  # the last frame not written

    def keep(self, frame: int, value: np.ndarray) -> list[tuple[int, np.ndarray]]:
        """The (frame, value) samples to write for `value` at `frame` (frames in order)."""
        moved = (
            self.written is None
            or value.shape != self.written.shape
            or float(np.abs(value - self.written).max(initial=0.0)) > self.limit
        )
        if not moved:
            self.skipped = (frame, value)
            return []
        out = [] if self.skipped is None else [self.skipped]
        out.append((frame, value))
        self.written, self.skipped = value, None
        return out


@dataclass
class Owner:
    """One BasisCurves: the curves it holds, the creature carrying it (-1: none) and
    its attributes' paths and held samples."""

    chosen: np.ndarray
    creature: int
    curves: UsdGeom.BasisCurves
    points: Sdf.Path
    widths: Sdf.Path
    extent: Sdf.Path
    held_points: Held
    held_widths: Held


class CurvesTrack:
    """One curves track: a BasisCurves per owner, carried by its mantle with `mantles`."""

    def __init__(
        self,
        pxr: ModuleType,
        layer: StreamedLayer,
        header: dict[str, Any],
        track: TakeTrack,
        mantles: np.ndarray | None = None,
    ) -> None:
        self.pxr, self.layer, self.track, self.mantles = pxr, layer, track, mantles
        UsdGeom = pxr.UsdGeom
        owners = np.asarray(header[track.key]["creatures"], dtype=np.int64)
        names = [c["name"] for c in header["creatures"]]
        self.owners: list[Owner] = []
        self.carriers: dict[int, tuple[Sdf.Path, Sdf.Path, Held]] = {}  # translate, orient
        carried = mantles is not None
        for owner in sorted(set(owners.tolist())):
            if 0 <= owner < len(names):
                name = f"{names[owner]}/{track.folder}/{track.item}"
                path = f"/World/{unique_path(name, FOLDERS | {track.folder})}"
            else:  # curves no creature owns
                path = f"/World/{track.folder}/{track.item}"
            folder = UsdGeom.Xform.Define(layer.stage, path.rsplit("/", 1)[0])
            if carried and owner >= 0:
                self.carriers[owner] = (
                    folder.AddTranslateOp(UsdGeom.XformOp.PrecisionFloat).GetAttr().GetPath(),
                    folder.AddOrientOp().GetAttr().GetPath(),
                    Held(0.0),  # the mantle is its root's origin: written where it moves
                )
            curves = UsdGeom.BasisCurves.Define(layer.stage, path)
            curves.CreateTypeAttr(UsdGeom.Tokens.linear)
            curves.CreateWrapAttr(UsdGeom.Tokens.nonperiodic)
            curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
            limit = 0.5 * TOLERANCE if carried and owner >= 0 else -1.0  # -1: every frame
            self.owners.append(
                Owner(
                    chosen=np.flatnonzero(owners == owner),
                    creature=owner if carried else -1,
                    curves=curves,
                    points=curves.CreatePointsAttr().GetPath(),
                    widths=curves.CreateWidthsAttr().GetPath(),
                    extent=curves.CreateExtentAttr().GetPath(),
                    held_points=Held(limit),
                    held_widths=Held(0.0 if carried else -1.0),
                )
            )

    def add(self, first: int, chunk: Take, roots: RootFrames | None = None) -> None:
        """The chunk's samples (frames `first` on); `roots`: the creatures' root frames
        (carried curves)."""
        all_points, all_widths = (chunk.tracks[name] for name in self.track.arrays)
        if first == 0:  # points per curve: the arrays' (the header does not say)
            for owner in self.owners:
                count = all_points.shape[2]
                owner.curves.CreateCurveVertexCountsAttr([count] * len(owner.chosen))
        carried = self._carried(first, chunk, roots)
        with self.layer.batch():
            for owner in self.owners:
                points = all_points[:, owner.chosen].reshape(chunk.frames, -1, 3)
                if carried is not None and owner.creature >= 0:
                    points = carried(owner.creature, points)
                widths = all_widths[:, owner.chosen].reshape(chunk.frames, -1)
                for row in range(chunk.frames):
                    self._frame(owner, first + row, points[row], widths[row])

    def _carried(
        self, first: int, chunk: Take, roots: RootFrames | None
    ) -> Callable[[int, np.ndarray], np.ndarray] | None:
        """Sample each carrying folder's mantle pose (in its root frame) for the chunk;
        returns `in_mantle(creature, points (n, P, 3))`: world points in its mantle's frame."""
        if self.mantles is None or not self.carriers:
            return None
        assert roots is not None, "carried curves need the creatures' root frames"
        Gf = self.pxr.Gf
        creatures = np.array(sorted(self.carriers), dtype=np.int64)
        pos = chunk.pos[:, self.mantles[creatures]].astype(np.float64)
        quat = chunk.quat[:, self.mantles[creatures]].astype(np.float64)
        quat /= np.sqrt(np.einsum("...i,...i->...", quat, quat))[..., None]
        where, turn = roots.local_pose(pos, quat, creatures)
        with self.layer.batch():
            for column, creature in enumerate(creatures.tolist()):
                translate, orient, held = self.carriers[creature]
                places = where[:, column].astype(np.float32)
                for row in range(chunk.frames):
                    w, x, y, z = turn[row, column].tolist()
                    for frame, at in held.keep(first + row, places[row]):
                        self.layer.sample(translate, frame, Gf.Vec3f(*at.tolist()), 12)
                    self.layer.sample(orient, first + row, Gf.Quatf(w, x, y, z), 16)
        column_of = {c: i for i, c in enumerate(creatures.tolist())}
        inverse = quat * np.array([1.0, -1.0, -1.0, -1.0])

        def in_mantle(creature: int, points: np.ndarray) -> np.ndarray:
            k = column_of[creature]
            moved = points.astype(np.float64) - pos[:, k, None]
            undo = np.broadcast_to(inverse[:, k, None], (*points.shape[:2], 4))
            return quat_rotate(undo, moved)

        return in_mantle

    def _frame(self, owner: Owner, frame: int, points: np.ndarray, widths: np.ndarray) -> None:
        """One frame of one BasisCurves, held where it does not move; the extent where
        the points or widths are written (of the latest written)."""
        Gf, Vt, layer = self.pxr.Gf, self.pxr.Vt, self.layer
        moved = owner.held_points.keep(frame, points)
        widened = owner.held_widths.keep(frame, widths)
        for at, value in moved:
            flat = np.ascontiguousarray(value, dtype=np.float32)
            layer.sample(owner.points, at, Vt.Vec3fArray.FromNumpy(flat), flat.nbytes)
        for at, value in widened:
            flat = np.ascontiguousarray(value, dtype=np.float32)
            layer.sample(owner.widths, at, Vt.FloatArray.FromNumpy(flat), flat.nbytes)
        if moved or widened:
            assert owner.held_points.written is not None and owner.held_widths.written is not None
            shown, wide = owner.held_points.written, owner.held_widths.written
            pad = 0.5 * float(wide.max(initial=0.0))
            low, high = shown.min(axis=0) - pad, shown.max(axis=0) + pad
            box = Vt.Vec3fArray([Gf.Vec3f(*low.tolist()), Gf.Vec3f(*high.tolist())])
            for at in sorted({at for at, _ in moved} | {at for at, _ in widened}):
                layer.sample(owner.extent, at, box, 24)
