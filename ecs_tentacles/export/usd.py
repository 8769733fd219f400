"""Take -> USD stage (needs the `usd` extra: `pip install 'ecs-tentacles[usd]'`).

    /World                                    Xform, the default prim
      /<c>                                    Xform (c: the creature's name)
        /<c>_mantle                           Xform: time-sampled translate + orient
          /<c>_mantle_geom                    Cylinder, axis Z, radius, height
        /<c>_tentacles/<c>_t<k>/<c>_t<k>_link<i>   Xform: time-sampled translate + orient
          /<c>_t<k>_link<i>_geom              Capsule, axis X, radius, height = spine
          /<c>_t<k>_link<i>_sucker<n>         locator: Xform at the sucker, `ecs:attached`
                                              sampled
        /<c>_<folder>/<c>_<item><j>           a points track's locator (the goals:
                                              <c>_goals/<c>_goal<j>): Xform at its
                                              position, visibility sampled (invisible
                                              once no longer live), `ecs:radius`
        /<c>_<folder>/<c>_<item>              a curves track (the fur guides:
                                              <c>_fur/<c>_guides): BasisCurves (linear),
                                              points and widths sampled
      /<folder>/<item>                        curves owned by no creature, if any
      /materials/<c>_material                 each creature's material: its sandbox
                                              colour (`ecs_tentacles.export.materials`),
                                              bound to its mantle and capsules
      /terrain                                the ground's meshes, on terrain
                                              (`ecs_tentacles.export.ground`)

Locators (suckers and points tracks' items: the goals) are written unless
`locators=False`; curves tracks (fur guides) always.

Every prim name is unique in the file (`ecs_tentacles.export.names`: importers name
objects globally and would add `.001` suffixes); tracks (`ecs_tentacles.take.tracks`)
are written by kind.

Poses are world-space (every parent is an identity transform), so the time samples
are the take's numbers: translate (double3) = pos, orient (quatf) = quat. Stage:
upAxis Z, metersPerUnit 1, timeCodesPerSecond = framesPerSecond = the take's fps,
time codes 0 .. frames - 1 (time code i is frame i, i / fps seconds).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.export.ground import write_usd_ground
from ecs_tentacles.export.materials import bind_usd, take_colours, usd_folder, usd_material
from ecs_tentacles.export.names import FOLDERS, unique_path
from ecs_tentacles.output.atomic import atomic_output
from ecs_tentacles.take import Take, TakeTrack
from ecs_tentacles.take.roster import spans


class UsdUnavailable(RuntimeError):
    """usd-core is not installed."""


def _pxr() -> Any:
    try:
        import pxr.Gf
        import pxr.Sdf
        import pxr.Usd
        import pxr.UsdGeom
        import pxr.Vt
    except ImportError:
        raise UsdUnavailable(
            "writing USD needs usd-core: pip install 'ecs-tentacles[usd]'"
        ) from None
    return pxr


def write_usd(
    take: Take,
    path: str | os.PathLike[str],
    progress: Callable[[int], object] | None = None,
    locators: bool = True,
) -> None:
    """Write `take` as a USD file (.usda text, .usdc or .usd binary), atomically.

    `progress(n)` is called as bodies are written (n bodies at a time); `locators=False`
    leaves suckers and goals out. Raises `TakeError` (one line) for a take USD cannot
    hold (non-finite numbers, bad names).
    """
    take.check_exportable(path)
    stage = build_stage(take, progress, locators)
    with atomic_output(path) as temporary:
        if not stage.GetRootLayer().Export(str(temporary)):
            raise OSError(f"{path}: USD could not write the file")


def new_stage(take: Take) -> Any:
    """An empty in-memory stage: z up, metres, the take's frame rate and frame range."""
    UsdGeom = _pxr().UsdGeom
    stage = _pxr().Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetTimeCodesPerSecond(take.fps)
    stage.SetFramesPerSecond(take.fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(take.frames - 1)
    return stage


def mark_rate(stage: Any, path: str, take: Take) -> None:
    """`ecs:fps` and `ecs:frames` on the prim at `path` (a creature's root): importers that
    ignore the stage's frame rate (Blender's) bring these along as custom properties, and
    `tools/blender_import.py` sets the scene from them."""
    Sdf = _pxr().Sdf
    prim = stage.GetPrimAtPath(path)
    prim.CreateAttribute("ecs:fps", Sdf.ValueTypeNames.Double, custom=True).Set(float(take.fps))
    prim.CreateAttribute("ecs:frames", Sdf.ValueTypeNames.Int, custom=True).Set(take.frames)


def key_visibility(stage: Any, path: str, shown: np.ndarray) -> None:
    """Visibility keys on the prim at `path` (a creature's root) where `shown` (per frame)
    changes: invisible while the creature is not there (`ecs_tentacles.take.roster`).
    Nothing is written for a creature there all along."""
    if shown.all():
        return
    UsdGeom = _pxr().UsdGeom
    attribute = UsdGeom.Imageable(stage.GetPrimAtPath(path)).CreateVisibilityAttr()
    for frame, visible in spans(shown):
        token = UsdGeom.Tokens.inherited if visible else UsdGeom.Tokens.invisible
        attribute.Set(token, frame)


def build_stage(
    take: Take, progress: Callable[[int], object] | None = None, locators: bool = True
) -> Any:
    """An in-memory `Usd.Stage` holding the take; `progress(1)` after each body."""
    pxr = _pxr()
    importlib.import_module("pxr.UsdShade")
    UsdGeom = pxr.UsdGeom
    stage = new_stage(take)
    root = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(root.GetPrim())
    header = take.header
    shown = take.visible()
    colours, materials = take_colours(take), usd_folder(take)
    for index, creature in enumerate(header["creatures"]):
        base = f"/World/{creature['name']}"
        UsdGeom.Xform.Define(stage, base)
        mark_rate(stage, base, take)
        key_visibility(stage, base, shown[:, index])
        colour = colours[creature["name"]]
        skin = (usd_material(pxr, stage, materials, creature["name"], colour), colour)
        _body(pxr, stage, take, creature["mantle"], skin)
        if progress is not None:
            progress(1)
        UsdGeom.Xform.Define(stage, f"/World/{unique_path(creature['name'] + '/tentacles')}")
        for k, chain in enumerate(creature["tentacles"]):
            folder = unique_path(f"{creature['name']}/tentacles/t{k}")
            UsdGeom.Xform.Define(stage, f"/World/{folder}")
            for index in chain:
                _body(pxr, stage, take, index, skin)
                if progress is not None:
                    progress(1)
    if locators:
        for index, sucker in enumerate(header["suckers"]):
            _sucker(pxr, stage, take, index, sucker)
    write_tracks(pxr, stage, take, locators)
    write_usd_ground(pxr, stage, take)
    return stage


def write_tracks(pxr: Any, stage: Any, take: Take, locators: bool = True) -> None:
    """Every track of the take onto the stage, by kind: curves, and with `locators` the
    points tracks' locators."""
    for track in take.track_list():
        if track.kind == "points":
            if not locators:
                continue
            for index, item in enumerate(take.header[track.key]):
                _locator(pxr, stage, take, track, index, item)
        elif take.tracks.get(track.arrays[0]) is not None:
            _curves(pxr, stage, take, track)


def _body(pxr: Any, stage: Any, take: Take, index: int, skin: tuple[Any, np.ndarray]) -> None:
    Gf, UsdGeom = pxr.Gf, pxr.UsdGeom
    body = take.header["bodies"][index]
    xform = UsdGeom.Xform.Define(stage, f"/World/{unique_path(body['name'])}")
    translate = xform.AddTranslateOp()  # double3
    orient = xform.AddOrientOp()  # quatf
    pos = take.pos[:, index].astype(np.float64).tolist()
    quat = take.quat[:, index].tolist()
    for frame in range(take.frames):
        translate.Set(Gf.Vec3d(*pos[frame]), frame)
        w, x, y, z = quat[frame]
        orient.Set(Gf.Quatf(w, Gf.Vec3f(x, y, z)), frame)
    radius, length = float(body["radius"]), float(body["length"])
    unique = unique_path(body["name"])
    path = f"/World/{unique}/{unique.rsplit('/', 1)[-1]}_geom"
    kind = UsdGeom.Cylinder if body["shape"] == "cylinder" else UsdGeom.Capsule
    geom = kind.Define(stage, path)
    geom.CreateAxisAttr(body["axis"])
    geom.CreateRadiusAttr(radius)
    geom.CreateHeightAttr(length)
    half = [radius, radius, radius]
    half["XYZ".index(body["axis"])] = 0.5 * length + (radius if kind is UsdGeom.Capsule else 0.0)
    geom.CreateExtentAttr([Gf.Vec3f(*(-h for h in half)), Gf.Vec3f(*half)])
    bind_usd(pxr, geom.GetPrim(), *skin)  # the creature's material (skin, colour)


def _sucker(pxr: Any, stage: Any, take: Take, index: int, sucker: dict[str, Any]) -> None:
    Gf, Sdf, UsdGeom = pxr.Gf, pxr.Sdf, pxr.UsdGeom
    xform = UsdGeom.Xform.Define(stage, f"/World/{unique_path(sucker['name'])}")
    xform.AddTranslateOp().Set(Gf.Vec3d(*sucker["offset"]))
    attached = xform.GetPrim().CreateAttribute("ecs:attached", Sdf.ValueTypeNames.Bool)
    values = take.sucker_attached[:, index].tolist()
    for frame in _changes(values):
        attached.Set(values[frame], frame)


def _locator(
    pxr: Any, stage: Any, take: Take, track: TakeTrack, index: int, item: dict[str, Any]
) -> None:
    Gf, Sdf, UsdGeom = pxr.Gf, pxr.Sdf, pxr.UsdGeom
    where, live = (take.tracks[name] for name in track.arrays)
    path = f"/World/{unique_path(item['name'], FOLDERS | {track.folder})}"
    UsdGeom.Xform.Define(stage, path.rsplit("/", 1)[0])  # the creature's folder of them
    xform = UsdGeom.Xform.Define(stage, path)
    xform.AddTranslateOp().Set(Gf.Vec3d(*where[index].astype(np.float64).tolist()))
    xform.GetPrim().CreateAttribute("ecs:radius", Sdf.ValueTypeNames.Double).Set(item["radius"])
    visibility = xform.CreateVisibilityAttr()
    values = live[:, index].tolist()
    for frame in _changes(values):
        token = UsdGeom.Tokens.inherited if values[frame] else UsdGeom.Tokens.invisible
        visibility.Set(token, frame)


def _curves(pxr: Any, stage: Any, take: Take, track: TakeTrack) -> None:
    Gf, Vt, UsdGeom = pxr.Gf, pxr.Vt, pxr.UsdGeom
    all_points, all_widths = (take.tracks[name] for name in track.arrays)
    owners = np.asarray(take.header[track.key]["creatures"], dtype=np.int64)
    names = [c["name"] for c in take.header["creatures"]]
    points_per_curve = all_points.shape[2]
    for owner in sorted(set(owners.tolist())):
        chosen = np.flatnonzero(owners == owner)
        if 0 <= owner < len(names):
            name = f"{names[owner]}/{track.folder}/{track.item}"
            path = f"/World/{unique_path(name, FOLDERS | {track.folder})}"
        else:  # curves no creature owns
            path = f"/World/{track.folder}/{track.item}"
        UsdGeom.Xform.Define(stage, path.rsplit("/", 1)[0])
        curves = UsdGeom.BasisCurves.Define(stage, path)
        curves.CreateTypeAttr(UsdGeom.Tokens.linear)
        curves.CreateWrapAttr(UsdGeom.Tokens.nonperiodic)
        curves.CreateCurveVertexCountsAttr([points_per_curve] * len(chosen))
        points_attr = curves.CreatePointsAttr()
        widths_attr = curves.CreateWidthsAttr()
        curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
        extent_attr = curves.CreateExtentAttr()
        for frame in range(take.frames):
            points = all_points[frame, chosen].reshape(-1, 3)
            widths = all_widths[frame, chosen].reshape(-1)
            points_attr.Set(Vt.Vec3fArray.FromNumpy(points), frame)
            widths_attr.Set(Vt.FloatArray.FromNumpy(widths), frame)
            pad = 0.5 * float(widths.max(initial=0.0))
            low, high = points.min(axis=0) - pad, points.max(axis=0) + pad
            extent_attr.Set([Gf.Vec3f(*low.tolist()), Gf.Vec3f(*high.tolist())], frame)


def _changes(values: list[Any]) -> list[int]:
    """Frames where a held (step) value changes, the first included."""
    return [i for i, v in enumerate(values) if i == 0 or v != values[i - 1]]
