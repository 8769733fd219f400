"""Baking: simulate a scene headless for some seconds and record every frame into a Take.

    plan = BakePlan.make("octopus", seconds=2.0, fps=30)
    take = bake(plan)                      # deterministic for a given scene and seed
    take.save("octopus.npz")

The take's frame rate may differ from the scene's: when it divides the scene's
`physics.fps` the bake records every k-th frame. Otherwise the simulation runs at a
multiple of the take's rate, so every take frame is a simulated frame, never an
interpolation: the multiple nearest the scene's rate whose frame is a whole number of
the scene's physics steps, keeping the scene's step (24 fps from a 60 fps scene of 8
substeps simulates at 48 fps of 10 substeps, 1/480 s each, recording every other
frame); when no multiple keeps it (23.976 fps), the smallest not below the scene's,
with the scene's substeps (a shorter step).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ecs_tentacles.export.glb_size import GlbSize, glb_note, glb_problem, glb_size, shapes_of_scene
from ecs_tentacles.export.kinds import output_kind
from ecs_tentacles.export.recording import Recording, scene_sha256
from ecs_tentacles.export.take_size import NPY_HEADERS, TakeSize, take_size
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.output.progress import status, step_frames
from ecs_tentacles.scene.load import load_scene_plugins, resolve_scene_path
from ecs_tentacles.scene.plugins import builtin
from ecs_tentacles.take import Take
from ecs_tentacles.take.read import MAX_FRAMES, MAX_HEADER_BYTES, MAX_TAKE_BYTES
from ecs_tentacles.take.tracks import TrackSize
from ecs_tentacles.world import World

if TYPE_CHECKING:
    from ecs_tentacles.export.skinned import Skin

GIB, MIB = 1024**3, 1024**2


def _count(value: float) -> str:
    """A count for a message: 2,400,001, or 6e+301 where digits would run on."""
    return f"{value:,.0f}" if value < 1e15 else f"{value:.3g}"


def _seconds(value: float) -> str:
    """Seconds for a message, rounded down to the millisecond (never up past a limit)."""
    return f"{math.floor(value * 1000) / 1000:,.3f}".rstrip("0").rstrip(".")


def _parts(size: TakeSize) -> str:
    """'7 bodies, 1 sucker and 250,000 fur guides of 16 points' (the parts with items)."""
    named = []
    for part in (p for p in size.parts if p.items):
        what = part.what if part.items > 1 else _one(part.what)
        named.append(f"{part.items:,} {what}" + (f" {part.each}" if part.each else ""))
    return ", ".join(named[:-1]) + (" and " if len(named) > 1 else "") + named[-1]


def _one(what: str) -> str:
    """'bodies' -> 'body', 'fur guides' -> 'fur guide'."""
    return what[:-3] + "y" if what.endswith("ies") else what.removesuffix("s")


@dataclass(frozen=True)
class BakePlan:
    """What a bake will do: the scene (validated, defaults in), timing and seed."""

    scene: dict[str, Any]
    source: str
    seconds: float
    fps: float  # of the take
    sim_fps: float  # of the simulation
    every: int  # simulated frames per take frame
    substeps: int  # physics steps per simulated frame
    seed: int
    folder: str | None = None  # the scene's folder: plugins from files are found there
    tracks: tuple[TrackSize, ...] = ()  # what the scene's plugins' take tracks will hold

    @classmethod
    def make(
        cls,
        scene: str | os.PathLike[str] | dict[str, object],
        options: WorldOptions | None = None,
        *,
        seconds: float,
        fps: float | None = None,
        **deprecated: object,
    ) -> BakePlan:
        """Load and validate `scene` (SceneError if bad) and work out the frame rates.

        `options` (`ecs_tentacles.options.WorldOptions`): `seed` over the scene's;
        `allow_systems` lets the scene's plugins from files or modules be imported, those
        of a dict scene found in `scene_dir` (default: the current folder); `lod` and
        `focus` are written into the plan's scene (the take's scene hash sees them).
        (`seed=`, `allow_systems=`, `scene_dir=` as keywords: deprecated.)
        """
        options = (options or WorldOptions()).given(deprecated, "BakePlan.make")
        allow_systems, seed, scene_dir = options.allow_systems, options.seed, options.scene_dir
        # absolute: a Ray worker runs in a folder of its own (distributed.driver)
        folder = str(Path(os.getcwd() if scene_dir is None else scene_dir).resolve())
        if isinstance(scene, dict):
            where = Path(folder)
            data, plugins = load_scene_plugins(scene, allow_systems=allow_systems, scene_dir=where)
            source = "<dict>"
        else:
            path = resolve_scene_path(os.fspath(scene))
            data, plugins = load_scene_plugins(path, allow_systems=allow_systems)
            source, folder = str(path), str(path.resolve().parent)
        if not (seconds > 0 and math.isfinite(seconds)):
            raise ValueError(f"seconds must be a positive number, got {seconds}")
        scene_fps = float(data["physics"]["fps"])
        take_fps = scene_fps if fps is None else float(fps)
        if not (take_fps > 0 and math.isfinite(take_fps)):
            raise ValueError(f"fps must be a positive number, got {fps}")
        every, sim_fps, substeps = simulation_rate(
            scene_fps, take_fps, int(data["physics"]["substeps"])
        )
        return cls(
            scene=options.scene_with_lod(data),
            source=source,
            seconds=float(seconds),
            fps=take_fps,
            sim_fps=sim_fps,
            every=every,
            substeps=substeps,
            seed=int(data["seed"] if seed is None else seed),
            folder=folder,
            tracks=tuple(size for plugin in plugins for size in plugin.take_sizes(data)),
        )

    @property
    def intervals(self) -> int:
        """Take frames after the first (frame 0 is the built pose)."""
        return round(self.seconds * self.fps)

    @property
    def frames(self) -> int:
        """Frames in the take, frame 0 included."""
        return self.intervals + 1

    @property
    def steps(self) -> int:
        """Simulated frames the bake runs."""
        return self.intervals * self.every

    def size_problem(self) -> str | None:
        """Why the take this plan makes could not be held or read back (one line), or None.

        Checked before anything is built: a take has at most `MAX_FRAMES` frames,
        `MAX_TAKE_BYTES` in all and `MAX_HEADER_BYTES` of header, as counted from the
        scene (`export.take_size`: the bodies, the suckers and the plugins' tracks, the
        fur's guide curves among them). The message says what would fit.
        """
        frames = self.seconds * self.fps + 1  # a float: no overflow, whatever was asked
        if frames > MAX_FRAMES + 0.5:
            return (
                f"{self.seconds:g} s at {self.fps:g} fps is {_count(frames)} frames; a take holds"
                f" at most {MAX_FRAMES} (bake fewer seconds or at a lower --fps)"
            )
        size = take_size(self.scene, self.tracks)
        header = size.fixed_bytes - NPY_HEADERS  # at most: a point's position counts too
        if header > MAX_HEADER_BYTES:
            return (
                f"the take's header would be {header / MIB:,.0f} MiB for {_parts(size)};"
                f" a take's header holds at most {MAX_HEADER_BYTES / MIB:g} MiB (bake fewer"
                " creatures)"
            )
        total = size.at_once(self.frames)
        if total <= MAX_TAKE_BYTES:
            return None
        most = max(size.parts, key=lambda part: part.items * part.frame_bytes)
        share = self.frames * most.items * most.frame_bytes + most.fixed_bytes
        return (
            f"{self.frames:,} frames of {_parts(size)} would be {total / GIB:.1f} GiB to read at"
            f" once, {share / GIB:.1f} GiB of it the {most.what}; a take's reader decodes at"
            f" most {MAX_TAKE_BYTES / GIB:g} GiB at once: {self._what_fits(size, most)}"
        )

    def glb_size(self, skin: Skin | None, locators: bool | None) -> GlbSize:
        """What a glb of this bake holds, at most, as `skin` (None: rigid) and `locators`
        would write it: counted from the scene before anything is built."""
        shapes = shapes_of_scene(self.scene, self.frames)
        detail, keys = (None, None) if skin is None else (skin.detail, skin.keys)
        return glb_size(shapes, detail, keys, locators)

    def glb_problem(
        self, out: str | os.PathLike[str], skin: Skin | None, locators: bool | None
    ) -> str | None:
        """Why the glb `out` cannot hold what this plan bakes (one line), or None (and
        None when `out` is not a glb; `export.glb_size`)."""
        if output_kind(out) != "gltf":
            return None
        fits = (".usdc", ".npz") if self.size_problem() is None else ()
        return glb_problem(out, self.glb_size(skin, locators), fits)

    def glb_note(
        self,
        out: str | os.PathLike[str],
        skin: Skin | None,
        locators: bool | None,
        memory: int | None = None,
    ) -> str | None:
        """A note when the glb `out` fits glTF but Blender's importer would need more than
        `memory` (this machine's) to open it, else None (`export.glb_size.glb_note`)."""
        if output_kind(out) != "gltf":
            return None
        return glb_note(out, self.glb_size(skin, locators), memory)

    def _what_fits(self, size: TakeSize, most: TrackSize) -> str:
        """The most seconds a take holds at this rate, and the most of the largest part
        (a plugin's track) at these seconds: 'bake at most 0.55 s at 60 fps or at most
        210,000 fur guides'."""
        fits = []
        tracks = size.frame_bytes - size.chunked_frame_bytes
        frames = (MAX_TAKE_BYTES - size.fixed_bytes) // max(tracks, 1)
        if frames >= 2:
            fits.append(f"bake at most {_seconds((frames - 1) / self.fps)} s at {self.fps:g} fps")
        if most in size.parts[2:]:  # a plugin's track, not the bodies or suckers
            others = size.total(self.frames) - self.frames * most.items * most.frame_bytes
            room = MAX_TAKE_BYTES - (others - most.fixed_bytes)
            each = self.frames * most.frame_bytes + most.fixed_bytes / max(most.items, 1)
            if room >= 0:
                fits.append(f"at most {math.floor(room / each):,} {most.what}")
        return " or ".join(fits) or "bake fewer creatures"

    @property
    def scene_sha256(self) -> str:
        """Hash of the scene as loaded (before a frame-rate change for the bake)."""
        return scene_sha256(self.scene)

    def world(self, options: WorldOptions | None = None) -> World:
        """Build the world to bake, at the simulation frame rate, with `options`' code
        allowed, threads and creatures (`only`); the plan's seed, and its scene's level
        of detail (`make` wrote the options' there)."""
        scene = dict(self.scene)
        scene["physics"] = {**scene["physics"], "fps": self.sim_fps, "substeps": self.substeps}
        own = (options or WorldOptions()).but(
            seed=self.seed, scene_dir=self.folder, lod=None, focus=None
        )
        return World.from_scene(scene, own)


MAX_SUBSTEPS = 100  # the schema's physics.substeps maximum


def simulation_rate(scene_fps: float, take_fps: float, substeps: int) -> tuple[int, float, int]:
    """(simulated frames per take frame, simulation fps, substeps) for a take at `take_fps`.

    A take rate that divides the scene's keeps the scene's clock. Otherwise the
    simulation runs at a multiple of the take's rate whose frame is a whole number of
    the scene's physics steps (the same MuJoCo timestep as `run`), the multiple nearest
    the scene's rate (the higher on a tie; at most twice the scene's rate, or the take's
    own rate if that is faster; at most the schema's 100 substeps); failing
    that, at the smallest multiple not below the scene's rate with the scene's substeps.
    """
    ratio = scene_fps / take_fps
    nearest = round(ratio)
    if nearest >= 1 and math.isclose(ratio, nearest, rel_tol=1e-9):
        return int(nearest), scene_fps, substeps
    steps_per_second = scene_fps * substeps
    keeping_step = {}  # every -> substeps, where a frame is a whole number of steps
    for every in range(1, max(1, math.floor(2 * ratio)) + 1):
        per_frame = steps_per_second / (take_fps * every)
        whole = round(per_frame)
        if 1 <= whole <= MAX_SUBSTEPS and math.isclose(per_frame, whole, rel_tol=1e-9):
            keeping_step[every] = whole
    if keeping_step:
        every = min(keeping_step, key=lambda e: (abs(take_fps * e - scene_fps), -e))
        return every, take_fps * every, keeping_step[every]
    every = max(1, math.ceil(ratio))
    return every, take_fps * every, substeps


def bake(
    plan: BakePlan,
    options: WorldOptions | None = None,
    *,
    progress: bool = True,
    on_world: Callable[[World], None] | None = None,
    on_steps: Callable[[int], None] | None = None,
    **deprecated: object,
) -> Take:
    """Run the plan and return the take; a tqdm bar with ETA goes to stderr when `progress`.

    `options` build the world (`BakePlan.world`: code allowed, `threads` stepping the
    physics groups, `only` the creatures at those scene indices: a shard).
    `on_world(world)` is called once the world is built (tests use it to add systems);
    `on_steps(n)` is told of every `n` frames simulated. (`allow_systems=`, `threads=`,
    `only=` as keywords: deprecated.)
    """
    options = (options or WorldOptions()).given(deprecated, "bake")
    with status("bake: building the world", progress=progress):
        world = plan.world(options)
    try:
        if on_world is not None:
            on_world(world)
        recording = builtin(
            "record", every=plan.every, scene_sha256=plan.scene_sha256, capacity=plan.frames
        )
        assert isinstance(recording, Recording)  # the record plugin
        world.add_plugin(recording)
        step_frames(world, plan.steps, progress=progress, desc="bake", on_steps=on_steps)
        with status(f"bake: gathering {plan.frames} frames", progress=progress):
            return recording.finish()  # the recorder's arrays: the frames are held once
    finally:
        world.close()


def bake_to_file(
    plan: BakePlan,
    out: str | os.PathLike[str],
    options: WorldOptions | None = None,
    *,
    progress: bool = True,
    on_world: Callable[[World], None] | None = None,
    accept: Callable[[dict[str, object]], bool] | None = None,
    **deprecated: object,
) -> dict[str, Any] | None:
    """Run the plan, writing the take to `out` as the frames come (`take.writer`: a
    chunk of frames held at a time, so memory does not grow with the shot); returns the
    header written. Stopped (an exception, Ctrl-C), it leaves no file and no chunks;
    `accept(header)` False at the end: no file either, and None. `options`: as `bake`."""
    from ecs_tentacles.take.writer import TakeWriter

    options = (options or WorldOptions()).given(deprecated, "bake_to_file")
    with status("bake: building the world", progress=progress):
        world = plan.world(options)
    try:
        if on_world is not None:
            on_world(world)
        with TakeWriter(out) as writer:
            recording = builtin(
                "record",
                every=plan.every,
                scene_sha256=plan.scene_sha256,
                capacity=plan.frames,
                writer=writer,
            )
            world.add_plugin(recording)
            step_frames(world, plan.steps, progress=progress, desc="bake")
            with status(f"bake: writing {out}", progress=progress):
                header: dict[str, Any] = recording.finish_stream()  # type: ignore[attr-defined]
            if accept is not None and not accept(header):
                writer.discard()
                return None
        return header
    finally:
        world.close()
