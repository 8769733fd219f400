"""The sandbox's simulation, apart from its window: the world built from a scene,
rebuilt from an edited scene and reset from the file, stepped at the scene's fixed rate
(`tick` catches up with the clock, at most `MAX_CATCH_UP` seconds a call), saved and
restored (F5 / F9), its roster written as a scene, and its level of detail told what
the player looks at. No window and no GL: `render.sandbox.Sandbox` draws a session and
turns the mouse and keys into its calls.

Reads and writes: the `World` it owns (it closes the old one when it builds a new one).
Problems a player should see (a scene that no longer builds, a restore that names a
creature removed since, a save that failed) go to `say(ok, text)`, one line each.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from ecs_tentacles.creatures.roster_save import save_roster
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.save import default_file_name
from ecs_tentacles.snapshot import Snapshot, SnapshotMismatch
from ecs_tentacles.system import SystemFailure
from ecs_tentacles.world import World

MAX_CATCH_UP = 0.25  # seconds of physics to catch up at most per display frame
FOCUS_RADIUS = 1.5  # m around the camera's target where creatures must run full physics
# The camera's target region runs full only from this close (m): from here its 3 m fill a
# third of the view's height (45 degrees); farther, its creatures are too small on screen
# for full physics to show, and a crowd framed whole (64 creatures: 30 m) keeps its frame.
CLOSE_UP = 12.0


class SandboxSession:
    """One scene's world as the sandbox runs it."""

    def __init__(
        self,
        scene: str | os.PathLike[str] | dict[str, object],
        options: WorldOptions | None = None,
        *,
        say: Callable[[bool, str], None] = lambda ok, text: None,
        **deprecated: object,
    ):
        """`options` build every world of the session (`ecs_tentacles.options`); their
        `focus` (x, y, radius in m) pins the full-physics region instead of the camera's.
        (`seed=`, `lod=`... as keywords: deprecated, `WorldOptions.given`.)"""
        self.scene = scene
        self.options = (options or WorldOptions()).given(deprecated, "SandboxSession")
        self.say = say
        self.world = self.build(scene)
        # plugin files of an edited (dict) scene are looked up where the first one's were
        self.options = self.options.but(scene_dir=self.world.scene_dir)
        self.paused = False
        self.accumulator = 0.0
        self.saved_state: Snapshot | None = None

    @property
    def scene_dir(self) -> Path | None:
        """The folder plugin files are looked up in (the first scene's)."""
        return self.options.scene_dir

    # -- worlds ------------------------------------------------------------------------
    def build(self, scene: str | os.PathLike[str] | dict[str, object]) -> World:
        """A new world from `scene`, as this session builds them (its options: seed,
        threads, level of detail and pinned focus)."""
        return World.from_scene(scene, self.options)

    def rebuild(self, scene: dict[str, object]) -> World:
        """The world rebuilt from an edited scene (the old one closed); raises if it
        does not build."""
        self.world.close()
        self.saved_state = None  # a snapshot belongs to the world it came from
        self.scene = scene
        self.world = self.build(scene)
        return self.world

    def reset(self) -> World | None:
        """The world built again from the scene; None, and the old world kept, if the
        scene or a plugin's code does not build now (`say` tells why)."""
        try:
            world = self.build(self.scene)
        except (SceneError, SystemFailure) as error:
            self.say(False, f"not reset: {' '.join(str(error).split())}")
            return None
        self.saved_state = None
        self.world.close()
        self.world = world
        return world

    # -- level of detail -----------------------------------------------------------------
    @property
    def camera_focus(self) -> bool:
        """True when the level of detail's focus follows the camera (none is pinned)."""
        return self.options.focus is None and self.world.lod.settings.focus is None

    def steer_lod(self, target: np.ndarray, selected: Iterable[int], distance: float) -> None:
        """Tell the level of detail what the player looks at: the selected creatures run
        full, and (unless a focus is pinned) those within `FOCUS_RADIUS` of the camera's
        `target` (x, y) while the camera is within `CLOSE_UP` of it (`distance`); the
        full budget is not filled with creatures the camera is not on (a crowd framed
        whole keeps real time)."""
        lod = self.world.lod
        lod.select(selected)
        if self.camera_focus:
            close = distance <= CLOSE_UP
            lod.focus(np.asarray(target)[:2] if close else None, FOCUS_RADIUS, fill=False)

    # -- time ----------------------------------------------------------------------------
    def due(self, dt: float) -> int:
        """Physics frames due after `dt` seconds of the clock (0 while paused), at most
        `MAX_CATCH_UP` seconds' worth."""
        if self.paused:
            return 0
        frame = self.world.settings.dt
        self.accumulator = min(self.accumulator + dt, MAX_CATCH_UP)
        frames = 0
        while self.accumulator >= frame:
            frames += 1
            self.accumulator -= frame
        return frames

    def save_state(self) -> None:
        """Remember the whole simulation state (F5)."""
        self.saved_state = self.world.snapshot()

    def load_state(self) -> bool:
        """Go back to the state saved with F5 (F9); False if none was saved, or if it
        names a creature removed since (`say` tells)."""
        if self.saved_state is None:
            return False
        try:
            self.world.restore(self.saved_state)
        except SnapshotMismatch as error:
            self.say(False, str(error))
            return False
        self.accumulator = 0.0
        return True

    def save_roster(self, path: str | os.PathLike[str] | None = None) -> Path | None:
        """Write the roster, goals and settings as they are now to a scene file (Ctrl+S:
        `<scene>_directed.json` in the working folder, the name made safe: a scene's
        name never chooses a folder); None and a message if it would not load
        (`ecs_tentacles.creatures.roster_save`)."""
        name = (self.world.scene or {}).get("name")
        target = Path(path) if path is not None else Path(default_file_name(name, "_directed.json"))
        try:
            saved = save_roster(self.world, target)
        except (SceneError, OSError) as error:
            self.say(False, f"not saved: {' '.join(str(error).split())}")
            return None
        self.say(True, f"saved {saved}")
        return saved
