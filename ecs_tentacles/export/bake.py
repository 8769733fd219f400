"""Baking: simulate a scene headless for some seconds and record every frame into a Take.

    plan = BakePlan.make("octopus", seconds=2.0, fps=30)
    take = bake(plan)                      # deterministic for a given scene and seed
    take.save("octopus.npz")

The take's frame rate may differ from the scene's: when it divides the scene's
`physics.fps` the bake records every k-th frame; otherwise the simulation runs at the
smallest multiple of the take's rate not below the scene's (24 fps from a 60 fps
scene simulates at 72 fps, recording every third frame), so every take frame is a
simulated frame, never an interpolation.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Collection
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ecs_tentacles.export.recording import Recording, scene_sha256
from ecs_tentacles.output.progress import status, step_frames
from ecs_tentacles.scene.construction import tentacle_params
from ecs_tentacles.scene.load import load_scene, load_scene_plugins, resolve_scene_path
from ecs_tentacles.scene.plugins import builtin
from ecs_tentacles.take import Take
from ecs_tentacles.take.read import MAX_FRAMES, MAX_TAKE_BYTES
from ecs_tentacles.world import World


def _count(value: float) -> str:
    """A count for a message: 2,400,001, or 6e+301 where digits would run on."""
    return f"{value:,.0f}" if value < 1e15 else f"{value:.3g}"


POSE_BYTES = 7 * 4  # a body's position and quaternion in a frame (float32)
SUCKER_BYTES = 1 + 3 * 4  # attached flag and anchor


def scene_sizes(scene: dict[str, Any]) -> tuple[int, int]:
    """(bodies, suckers) a loaded scene's creatures have: mantles and links; suckers at
    most (the suckers plugin may be off)."""
    bodies = suckers = 0
    for creature in scene["creatures"]:
        tentacles = creature["tentacles"]
        for k in range(tentacles["count"]):
            params = tentacle_params(tentacles, k)
            bodies += params["links"]
            suckers += params["links"] if params.get("suckers") == "every_link" else 1
        bodies += 1
    return bodies, suckers


@dataclass(frozen=True)
class BakePlan:
    """What a bake will do: the scene (validated, defaults in), timing and seed."""

    scene: dict[str, Any]
    source: str
    seconds: float
    fps: float  # of the take
    sim_fps: float  # of the simulation
    every: int  # simulated frames per take frame
    seed: int
    folder: str | None = None  # the scene's folder: plugins from files are found there

    @classmethod
    def make(
        cls,
        scene: str | os.PathLike[str] | dict[str, Any],
        *,
        seconds: float,
        fps: float | None = None,
        seed: int | None = None,
        allow_systems: bool = False,
        scene_dir: str | os.PathLike[str] | None = None,
    ) -> BakePlan:
        """Load and validate `scene` (SceneError if bad) and work out the frame rates.

        `allow_systems` lets the scene's plugins from files or modules be imported; those
        of a dict scene are found in `scene_dir` (default: the current folder).
        """
        # absolute: a Ray worker runs in a folder of its own (distributed.driver)
        folder = str(Path(os.getcwd() if scene_dir is None else scene_dir).resolve())
        if isinstance(scene, dict):
            where = Path(folder)
            data = load_scene_plugins(scene, allow_systems=allow_systems, scene_dir=where)[0]
            source = "<dict>"
        else:
            path = resolve_scene_path(os.fspath(scene))
            source, data = str(path), load_scene(path, allow_systems=allow_systems)
            folder = str(path.resolve().parent)
        if not (seconds > 0 and math.isfinite(seconds)):
            raise ValueError(f"seconds must be a positive number, got {seconds}")
        scene_fps = float(data["physics"]["fps"])
        take_fps = scene_fps if fps is None else float(fps)
        if not (take_fps > 0 and math.isfinite(take_fps)):
            raise ValueError(f"fps must be a positive number, got {fps}")
        every, sim_fps = simulation_rate(scene_fps, take_fps)
        return cls(
            scene=data,
            source=source,
            seconds=float(seconds),
            fps=take_fps,
            sim_fps=sim_fps,
            every=every,
            seed=int(data["seed"] if seed is None else seed),
            folder=folder,
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

        Checked before anything is built: a take has at most `MAX_FRAMES` frames and
        `MAX_TAKE_BYTES` of arrays (poses are 28 bytes per body and frame).
        """
        frames = self.seconds * self.fps + 1  # a float: no overflow, whatever was asked
        if frames > MAX_FRAMES + 0.5:
            return (
                f"{self.seconds:g} s at {self.fps:g} fps is {_count(frames)} frames; a take holds"
                f" at most {MAX_FRAMES} (bake fewer seconds or at a lower --fps)"
            )
        bodies, suckers = scene_sizes(self.scene)
        size = self.frames * (bodies * POSE_BYTES + suckers * SUCKER_BYTES)
        if size > MAX_TAKE_BYTES:
            return (
                f"{self.frames} frames of {bodies} bodies would be {size / 1024**3:.1f} GiB;"
                f" a take holds at most {MAX_TAKE_BYTES / 1024**3:g} GiB (bake fewer seconds"
                " or at a lower --fps)"
            )
        return None

    @property
    def scene_sha256(self) -> str:
        """Hash of the scene as loaded (before a frame-rate change for the bake)."""
        return scene_sha256(self.scene)

    def world(
        self,
        *,
        allow_systems: bool = False,
        threads: int | None = None,
        only: Collection[int] | None = None,
    ) -> World:
        """Build the world to bake, at the simulation frame rate (`only`: see `World`)."""
        scene = dict(self.scene)
        scene["physics"] = {**scene["physics"], "fps": self.sim_fps}
        return World.from_scene(
            scene,
            seed=self.seed,
            allow_systems=allow_systems,
            threads=threads,
            only=only,
            scene_dir=self.folder,
        )


def simulation_rate(scene_fps: float, take_fps: float) -> tuple[int, float]:
    """(simulated frames per take frame, simulation fps) for a take at `take_fps`."""
    ratio = scene_fps / take_fps
    nearest = round(ratio)
    if nearest >= 1 and math.isclose(ratio, nearest, rel_tol=1e-9):
        return int(nearest), scene_fps
    every = max(1, math.ceil(ratio))
    return every, take_fps * every


def bake(
    plan: BakePlan,
    *,
    progress: bool = True,
    allow_systems: bool = False,
    on_world: Callable[[World], None] | None = None,
    threads: int | None = None,
    only: Collection[int] | None = None,
    on_steps: Callable[[int], None] | None = None,
) -> Take:
    """Run the plan and return the take; a tqdm bar with ETA goes to stderr when `progress`.

    `on_world(world)` is called once the world is built (tests use it to add systems).
    `threads` steps the physics groups on that many threads; `only` bakes just the
    creatures at those scene indices (a shard); `on_steps(n)` is told of every `n`
    frames simulated.
    """
    with status("bake: building the world", progress=progress):
        world = plan.world(allow_systems=allow_systems, threads=threads, only=only)
    try:
        if on_world is not None:
            on_world(world)
        recording = builtin(
            "record", every=plan.every, scene_sha256=plan.scene_sha256, capacity=plan.frames
        )
        assert isinstance(recording, Recording)  # the record plugin
        world.add_plugin(recording)
        step_frames(world, plan.steps, progress=progress, desc="bake", on_steps=on_steps)
        return recording.take()
    finally:
        world.close()


def output_kind(path: str | os.PathLike[str]) -> str | None:
    """'take', 'usd' or 'gltf' from a file name's suffix, None if unsupported."""
    suffix = Path(path).suffix.lower()
    return {".npz": "take", ".usd": "usd", ".usda": "usd", ".usdc": "usd", ".glb": "gltf"}.get(
        suffix
    )
