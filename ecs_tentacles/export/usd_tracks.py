"""A take's tracks and held values on a USD stage, written chunk of frames by chunk.

    tracks = UsdTracks(layer, header, static, locators=True)   # defines prims
    for first, chunk in source.chunks():
        tracks.add(first, chunk)                                # time samples

Tracks (`ecs_tentacles.take.tracks`) by kind: a points track's items (the goals) are
locators, `Xform`s at their position with `ecs:radius`, visibility keyed where their
live flag changes (written with `locators`); a curves track's curves (the fur guides)
are `BasisCurves` per owner (`ecs_tentacles.export.usd_curves`). Layout and names as
`ecs_tentacles.export.usd`'s docstring shows them. With `relative` (the skinned form,
whose creature roots move) positions are written in the creature's root frame
(`RootFrames`) and a creature's curves ride its mantle.

`Steps` keys a held (step) value where it changes, across chunks: visibility, a
sucker's `ecs:attached`. Reads the chunks it is handed; writes time samples through
the `StreamedLayer` (`ecs_tentacles.export.usd_layer`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.export.names import FOLDERS, unique_path
from ecs_tentacles.export.root_frames import RootFrames
from ecs_tentacles.export.usd_curves import CurvesTrack
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_pxr import usd_modules as _pxr
from ecs_tentacles.take import Take, TakeTrack
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.tracks import tracks_of

if TYPE_CHECKING:
    from pxr import Sdf


class Steps:
    """Held values of K items over chunks of frames: `changes` gives where a key goes."""

    def __init__(self, always_first: bool = True) -> None:
        self.always_first = always_first  # key frame 0 even when the value never changes
        self.last: np.ndarray | None = None
        self.first: np.ndarray | None = None  # frame 0's values (for `always_first=False`)
        self.keyed: np.ndarray | None = None  # items keyed at frame 0 so far

    def changes(self, first: int, values: np.ndarray) -> list[tuple[int, int, bool | int | float]]:
        """(frame, item, value) keys for the chunk `values` (n, K) starting at `first`:
        where an item's value differs from the frame before, and at frame 0 (with
        `always_first`; else frame 0 is keyed only once the item's value first changes)."""
        values = np.asarray(values)
        changed = np.zeros(values.shape, dtype=bool)
        changed[1:] = values[1:] != values[:-1]
        if self.last is not None:
            changed[0] = values[0] != self.last
        keys: list[tuple[int, int, bool | int | float]] = []
        if self.last is None:
            self.first = values[0].copy()
            self.keyed = np.full(values.shape[1], self.always_first)
            changed[0] = self.always_first
        assert self.first is not None and self.keyed is not None
        rows, items = np.nonzero(changed)
        late = sorted({int(k) for k in items.tolist()} - set(np.flatnonzero(self.keyed).tolist()))
        for k in late:  # its first change: frame 0's value goes in first
            keys.append((0, k, self.first[k].item()))
            self.keyed[k] = True
        keys += [
            (first + int(r), int(k), values[r, k].item())
            for r, k in zip(rows.tolist(), items.tolist(), strict=True)
        ]
        self.last = values[-1].copy()
        return keys


class UsdTracks:
    """Every track of a take on the stage: prims made at once, samples chunk by chunk."""

    def __init__(
        self,
        layer: StreamedLayer,
        header: dict[str, Any],
        static: dict[str, np.ndarray],
        locators: bool = True,
        relative: bool = False,
    ) -> None:
        pxr = _pxr()
        self.pxr, self.layer, self.header, self.relative = pxr, layer, header, relative
        self.static = static
        self.points: list[tuple[TakeTrack, list[tuple[Sdf.Path, Sdf.Path]], Steps]] = []
        self.curves: list[CurvesTrack] = []
        mantles = np.array([c["mantle"] for c in header["creatures"]], dtype=np.int64)
        for track in tracks_of(header):
            if track.kind == "points" and locators:
                self.points.append((track, self._locators(track, static), Steps()))
            elif track.kind == "curves" and header.get(track.key) is not None:
                carried = mantles if relative else None
                self.curves.append(CurvesTrack(pxr, layer, header, track, carried))

    def _locators(
        self, track: TakeTrack, static: dict[str, np.ndarray]
    ) -> list[tuple[Sdf.Path, Sdf.Path]]:
        """The points track's locators, placed (`relative`: their translate is sampled in
        add); the paths of their visibility and translate."""
        Gf, Sdf, UsdGeom = self.pxr.Gf, self.pxr.Sdf, self.pxr.UsdGeom
        stage, where = self.layer.stage, static[track.arrays[0]]
        paths = []
        for index, item in enumerate(self.header[track.key]):
            path = f"/World/{unique_path(item['name'], FOLDERS | {track.folder})}"
            UsdGeom.Xform.Define(stage, path.rsplit("/", 1)[0])  # the creature's folder
            xform = UsdGeom.Xform.Define(stage, path)
            translate = xform.AddTranslateOp()
            if not self.relative:
                translate.Set(Gf.Vec3d(*where[index].astype(np.float64).tolist()))
            radius = xform.GetPrim().CreateAttribute("ecs:radius", Sdf.ValueTypeNames.Double)
            radius.Set(item["radius"])
            paths.append((xform.CreateVisibilityAttr().GetPath(), translate.GetAttr().GetPath()))
        return paths

    def add(self, first: int, chunk: Take, roots: RootFrames | None = None) -> None:
        """The chunk's samples (frames `first` on): locators' visibility, curves' poses;
        with `roots` (`relative`), world positions in their creature's root frame."""
        layer = self.layer
        for curves in self.curves:
            curves.add(first, chunk, roots)
        tokens = (self.pxr.UsdGeom.Tokens.invisible, self.pxr.UsdGeom.Tokens.inherited)
        with layer.batch():  # Sdf edits only from here (no Usd API inside a change block)
            for track, paths, steps in self.points:
                shown = [visibility for visibility, _ in paths]
                key_steps(layer, shown, steps, first, chunk.tracks[track.arrays[1]], tokens)
                if roots is not None:
                    self._placed(track, [t for _, t in paths], first, chunk.frames, roots)

    def _placed(
        self, track: TakeTrack, paths: Sequence[object], first: int, frames: int, roots: RootFrames
    ) -> None:
        """Locators' translates at every frame of the chunk, in their creatures' frames."""
        Gf = self.pxr.Gf
        where = self.static[track.arrays[0]].astype(np.float64)
        owners = np.array([item["creature"] for item in self.header[track.key]], np.int64)
        local = roots.local(np.broadcast_to(where, (frames, *where.shape)), owners).tolist()
        for row, points in enumerate(local):
            for path, point in zip(paths, points, strict=True):
                self.layer.sample(path, first + row, Gf.Vec3d(*point), 24)


class Visibility:
    """Creatures' visibility (their root prims at `roots`), keyed where the take's roster
    (`creature_visible`) says one came or went; nothing for a creature there all along."""

    def __init__(self, layer: StreamedLayer, roots: list[str]) -> None:
        UsdGeom = _pxr().UsdGeom
        self.layer, self.roots = layer, roots
        self.tokens = (UsdGeom.Tokens.invisible, UsdGeom.Tokens.inherited)
        self.Sdf = _pxr().Sdf
        self.steps = Steps(always_first=False)

    def add(self, first: int, chunk: Take) -> None:
        """Keys for the chunk's frames (`first` on), where a creature's changes."""
        shown = chunk.tracks.get(take_roster.ARRAY)
        if shown is None:
            return
        changed = self.steps.changes(first, shown)
        if not changed:
            return
        UsdGeom, stage = _pxr().UsdGeom, self.layer.stage
        for creature in sorted({item for _, item, _ in changed}):
            prim = UsdGeom.Imageable(stage.GetPrimAtPath(self.roots[creature]))
            prim.CreateVisibilityAttr()  # made when first needed (Usd API: outside a batch)
        with self.layer.batch():
            for frame, creature, value in changed:
                path = f"{self.roots[creature]}.visibility"
                self.layer.sample(self.Sdf.Path(path), frame, self.tokens[int(bool(value))])


def key_steps(
    layer: StreamedLayer, paths: Sequence[object], steps: Steps, first: int, values: np.ndarray,
    tokens: tuple[str, str] | None = None,
) -> None:  # fmt: skip
    """Key the held `values` (n, K) of the chunk at `first` on the attributes `paths`
    (one per item) where they change; `tokens` (false, true): what a bool becomes."""
    for frame, item, value in steps.changes(first, values):
        layer.sample(paths[item], frame, value if tokens is None else tokens[int(bool(value))])
