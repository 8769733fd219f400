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

The take is read and written a chunk of frames at a time (`TakeChunks`: a take in
memory; a take file opened for streaming gives the same), the samples saved to the
file as they come (`ecs_tentacles.export.usd_layer`), tracks by
`ecs_tentacles.export.usd_tracks`.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.export.ground import write_usd_ground
from ecs_tentacles.export.materials import bind_usd, take_colours, usd_folder, usd_material
from ecs_tentacles.export.names import unique_path
from ecs_tentacles.export.take_chunks import ChunkSource, TakeChunks
from ecs_tentacles.export.usd_layer import StreamedLayer
from ecs_tentacles.export.usd_pxr import UsdUnavailable, usd_modules
from ecs_tentacles.export.usd_tracks import Steps, UsdTracks, Visibility, key_steps
from ecs_tentacles.output.atomic import atomic_output
from ecs_tentacles.take import Take
from ecs_tentacles.take.header_entries import HeaderBody, HeaderSucker

if TYPE_CHECKING:
    from pxr import Sdf, Usd, UsdShade

__all__ = ["UsdUnavailable", "build_stage", "mark_rate", "set_timing", "static_take", "write_usd"]


_pxr = usd_modules  # the name the other USD writers import


def write_usd(
    take: Take | ChunkSource,
    path: str | os.PathLike[str],
    progress: Callable[[int], object] | None = None,
    locators: bool = True,
) -> None:
    """Write `take` (in memory, or a stream of chunks) as a USD file (.usda text, .usdc
    or .usd binary), atomically, a chunk of frames at a time.

    `progress(n)` is called as n more frames are written; `locators=False` leaves
    suckers and goals out. Raises `TakeError` (one line) for a take USD cannot hold
    (non-finite numbers, bad names).
    """
    if isinstance(take, Take):
        take.check_exportable(path)
        take = TakeChunks(take)
    with atomic_output(path) as temporary:
        layer = StreamedLayer(temporary)
        _fill(layer, take, progress, locators)
        layer.finish()


def build_stage(
    take: Take, progress: Callable[[int], object] | None = None, locators: bool = True
) -> Usd.Stage:
    """An in-memory `Usd.Stage` holding the take; `progress(n)` as n frames are done."""
    layer = StreamedLayer(None)
    _fill(layer, TakeChunks(take), progress, locators)
    return layer.stage


def _fill(
    layer: StreamedLayer,
    source: ChunkSource,
    progress: Callable[[int], object] | None,
    locators: bool,
) -> None:
    """Every prim of the take on `layer`'s stage, then its frames chunk by chunk."""
    pxr = _pxr()
    importlib.import_module("pxr.UsdShade")
    UsdGeom = pxr.UsdGeom
    stage, header = layer.stage, source.header
    set_timing(stage, source.fps, source.frames)
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    still = static_take(source)
    colours, materials = take_colours(still), usd_folder(still)
    poses: list[tuple[int, Sdf.Path, Sdf.Path]] = []  # (body, translate path, orient path)
    roots = []
    for creature in header["creatures"]:
        name = creature["name"]
        base = f"/World/{name}"
        UsdGeom.Xform.Define(stage, base)
        roots.append(base)
        mark_rate(stage, base, source.fps, source.frames)
        colour = colours[creature["name"]]
        skin = (usd_material(pxr, stage, materials, creature["name"], colour), colour)
        poses.append(_body(pxr, stage, header["bodies"], creature["mantle"], skin))
        UsdGeom.Xform.Define(stage, f"/World/{unique_path(creature['name'] + '/tentacles')}")
        for k, chain in enumerate(creature["tentacles"]):
            UsdGeom.Xform.Define(stage, f"/World/{unique_path(f'{name}/tentacles/t{k}')}")
            poses += [_body(pxr, stage, header["bodies"], index, skin) for index in chain]
    attached = [_sucker(pxr, stage, sucker) for sucker in header["suckers"]] if locators else []
    visibility = Visibility(layer, roots)
    tracks = UsdTracks(layer, header, source.static, locators)
    write_usd_ground(pxr, stage, still)
    bodies = np.array([body for body, _, _ in poses], dtype=np.int64)
    held = Steps()
    for first, chunk in source.chunks():
        pos = chunk.pos[:, bodies].astype(np.float64)
        xyzw = chunk.quat[:, bodies][..., [1, 2, 3, 0]].astype(np.float32)
        with layer.batch():
            for row in range(chunk.frames):
                frame = first + row
                for (_, translate, orient), p, q in zip(
                    poses, pos[row].tolist(), xyzw[row].tolist(), strict=True
                ):
                    layer.sample(translate, frame, pxr.Gf.Vec3d(*p), 24)
                    layer.sample(orient, frame, pxr.Gf.Quatf(q[3], *q[:3]), 16)
            if attached:
                key_steps(layer, attached, held, first, chunk.sucker_attached)
        visibility.add(first, chunk)
        tracks.add(first, chunk)
        layer.flush()
        if progress is not None:
            progress(chunk.frames)


def static_take(source: ChunkSource) -> Take:
    """A take of no frames with `source`'s header and arrays without a frames axis:
    what the writers that need no frame read (colours, materials, the ground)."""
    header = source.header
    bodies, suckers = len(header["bodies"]), len(header["suckers"])
    return Take(
        header,
        np.zeros((0, bodies, 3), np.float32),
        np.zeros((0, bodies, 4), np.float32),
        np.zeros((0, suckers), bool),
        np.zeros((0, suckers, 3), np.float32),
        dict(source.static),
    )


def set_timing(stage: Usd.Stage, fps: float, frames: int) -> None:
    """Z up, metres, the take's frame rate and frame range on `stage`."""
    UsdGeom = _pxr().UsdGeom
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetTimeCodesPerSecond(fps)
    stage.SetFramesPerSecond(fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(frames - 1)


def mark_rate(stage: Usd.Stage, path: str, fps: float, frames: int) -> None:
    """`ecs:fps` and `ecs:frames` on the prim at `path` (a creature's root): importers that
    ignore the stage's frame rate (Blender's) bring these along as custom properties, and
    `tools/blender_import.py` sets the scene from them."""
    Sdf = _pxr().Sdf
    prim = stage.GetPrimAtPath(path)
    prim.CreateAttribute("ecs:fps", Sdf.ValueTypeNames.Double, custom=True).Set(float(fps))
    prim.CreateAttribute("ecs:frames", Sdf.ValueTypeNames.Int, custom=True).Set(frames)


def _body(
    pxr: ModuleType,
    stage: Usd.Stage,
    bodies: list[HeaderBody],
    index: int,
    skin: tuple[UsdShade.Material, np.ndarray],
) -> tuple[int, Sdf.Path, Sdf.Path]:
    """Body `index`'s Xform and shape; (index, its translate's and orient's paths)."""
    Gf, UsdGeom = pxr.Gf, pxr.UsdGeom
    body = bodies[index]
    xform = UsdGeom.Xform.Define(stage, f"/World/{unique_path(body['name'])}")
    translate = xform.AddTranslateOp()  # double3
    orient = xform.AddOrientOp()  # quatf
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
    return index, translate.GetAttr().GetPath(), orient.GetAttr().GetPath()


def _sucker(pxr: ModuleType, stage: Usd.Stage, sucker: HeaderSucker) -> Sdf.Path:
    """A sucker's locator under its link (a fixed offset); the path of `ecs:attached`."""
    Gf, Sdf, UsdGeom = pxr.Gf, pxr.Sdf, pxr.UsdGeom
    xform = UsdGeom.Xform.Define(stage, f"/World/{unique_path(sucker['name'])}")
    xform.AddTranslateOp().Set(Gf.Vec3d(*sucker["offset"]))
    attached = xform.GetPrim().CreateAttribute("ecs:attached", Sdf.ValueTypeNames.Bool)
    return attached.GetPath()
