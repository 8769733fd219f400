"""Hot reload: a plugin whose code is a file is re-imported when the file changes.

    reloader = Reloader(world)          # watches every plugin turned on `from` a .py file
    ...                                 # the user saves mywave.py
    for done in reloader.poll():        # cheap: one stat per file, at most every 0.5 s
        print(done.message)             # "reloaded mywave.py (wave)"

A reload imports the file again as a fresh module, makes a new plugin instance with
the same config and swaps each of its systems in under the old one's name
(`schedule.replace` + `setup`); systems that are new are added, systems that are gone
are removed. The world itself stays: entities, their ids and poses, the stores, the
plugin's resources (its build hooks and `resources` are not run again) and the frame
counter. A system keeps the `state_attributes` its old and new classes both declare.
A swapped system runs even if it was disabled (the usual case: it failed, the user
fixed the file). If the file fails to import, or the plugin or its systems fail to
be made or set up, nothing is swapped: the old systems keep running and the
`Reload` says why in one line. That includes code that calls `sys.exit` or raises
KeyboardInterrupt, a file that has become a symlink out of the scene's folder (the
folder rule is applied again on every reload) and an import or setup that takes longer
than `import_seconds` (5 s; the main thread's timer interrupts it).

The sandbox polls it from its clock; it needs no window (`ecs_tentacles.render` is
not imported).
"""

from __future__ import annotations

import contextlib
import pathlib
import signal
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from types import FrameType
from typing import TYPE_CHECKING

from ecs_tentacles.plugin import Plugin, calling
from ecs_tentacles.registry import App
from ecs_tentacles.scene.plugins import import_file, inside_scene_folder, instantiate, pick
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.world import World

INTERVAL = 0.5  # seconds between two looks at the files
IMPORT_SECONDS = 5.0  # longest a reload may take to import and set up a plugin


@dataclass
class Reload:
    """What one reload of one plugin did."""

    key: str  # the plugin's key (`plugins.<key>`)
    path: pathlib.Path
    swapped: list[str] = field(default_factory=list)  # systems now running the new code
    added: list[str] = field(default_factory=list)
    removed: list[str] = field(default_factory=list)
    error: str | None = None  # one line when nothing was swapped

    @property
    def message(self) -> str:
        """One line for the HUD and the log."""
        if self.error is not None:
            return f"{self.path.name}: not reloaded, old code keeps running: {self.error}"
        names = ", ".join([*self.swapped, *(f"+{n}" for n in self.added)])
        names += "".join(f", -{n}" for n in self.removed)
        return f"reloaded {self.path.name}" + (f" ({names.lstrip(', ')})" if names else "")


@dataclass
class _Watched:
    key: str
    relative: str  # the file as the scene names it, in `folder`
    folder: pathlib.Path
    path: pathlib.Path
    attr: str  # the class named after ':' in `from`, or ''
    stamp: tuple[int, int] | None


class Reloader:
    """Watches the files of a world's plugins and swaps in their new code."""

    def __init__(
        self, world: World, *, interval: float = INTERVAL, import_seconds: float = IMPORT_SECONDS
    ):
        self.world = world
        self.interval = interval
        self.import_seconds = import_seconds
        self._last = time.monotonic()
        self.watched: dict[str, _Watched] = {}
        for plugin in world.plugins:
            source = plugin.source or ""
            module_part, _, attr = source.partition(":")
            if not module_part.endswith(".py"):
                continue  # built in, a module or an entry point: not watched
            folder = world.scene_dir or pathlib.Path.cwd()
            path = (folder / module_part).resolve()
            watched = _Watched(plugin.key, module_part, folder, path, attr, _stamp(path))
            self.watched[plugin.key] = watched

    def poll(self, now: float | None = None) -> list[Reload]:
        """`check()` when `interval` seconds have passed since the last look, else []."""
        now = time.monotonic() if now is None else now
        if now - self._last < self.interval:
            return []
        self._last = now
        return self.check()

    def check(self) -> list[Reload]:
        """Reload every watched plugin whose file changed since the last look."""
        done = []
        for watched in self.watched.values():
            stamp = _stamp(watched.path)
            if stamp is None or stamp == watched.stamp:  # unchanged, or missing mid-save
                continue
            watched.stamp = stamp
            done.append(self.reload(watched.key))
        return done

    def reload(self, key: str) -> Reload:
        """Import plugin `key`'s file again and swap its systems in (see the module doc)."""
        watched = self.watched[key]
        result = Reload(key, watched.path)
        try:
            old = self.world.plugin(key)
            with time_limit(self.import_seconds):
                fresh, systems = self._make(watched, old)
        except (Exception, SystemExit, KeyboardInterrupt) as error:  # keep the old code running
            text = " ".join(str(error).split())
            result.error = f"{type(error).__name__}" + (f": {text}" if text else "")
            return result
        self._swap(old, fresh, systems, result)
        return result

    def _make(self, watched: _Watched, old: Plugin) -> tuple[Plugin, list[System]]:
        """The new plugin and its systems, set up; raises if any of it fails."""
        name = f"ecs_tentacles_user_plugins.{watched.key}"
        previous = sys.modules.get(name)
        where = f"plugins.{watched.key}"
        try:  # the folder rule again: the file may have become a symlink out of it
            module = import_file(inside_scene_folder(watched.relative, watched.folder, where),
                                 watched.key)  # fmt: skip
        except BaseException:
            if previous is not None:  # the old classes still look themselves up here
                sys.modules[name] = previous
            raise
        target = watched.path.name + (f":{watched.attr}" if watched.attr else "")
        made = pick(module, watched.attr, f"plugins.{watched.key}", target)
        fresh = instantiate(made, old.key, old.config, old.source)
        systems = fresh.systems()
        running = self._labels(old.key)
        for system in systems:
            system.plugin = old.key
            if system.name in running:
                before = self.world.schedule[system.name]
                for attribute in set(type(before).state_attributes) & set(system.state_attributes):
                    if hasattr(before, attribute):
                        setattr(system, attribute, getattr(before, attribute))
            system.setup(self.world)
        return fresh, systems

    def _labels(self, key: str) -> list[str]:
        """The names of the systems plugin `key` has in the schedule (disabled ones too)."""
        schedule = self.world.schedule
        return [n for n in [*schedule.names, *schedule.disabled()] if schedule[n].plugin == key]

    def _swap(self, old: Plugin, fresh: Plugin, systems: list[System], result: Reload) -> None:
        schedule = self.world.schedule
        running = self._labels(old.key)
        new = [s for s in systems if s.name not in running]
        for system in systems:
            if system.name in running:
                schedule.replace(system.name, system)
                if system.name in schedule.disabled():
                    schedule.enable(system.name)
                result.swapped.append(system.name)
        if new:
            schedule.add(*new)
            result.added += [s.name for s in new]
        for name in running:
            if name not in {s.name for s in systems}:
                schedule.remove(name)
                result.removed.append(name)
        plugins = self.world.plugins
        plugins[plugins.index(old)] = fresh
        self.world.registries.drop(old.key)  # the old entries go with the old plugin
        with calling(fresh, "build"):
            fresh.build(App(self.world.registries, fresh, self.world))


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise TimeoutError in the block after `seconds` (main thread, POSIX; else no limit)."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(
        signal, "setitimer"
    ):
        yield
        return

    def expire(signum: int, frame: FrameType | None) -> None:
        raise TimeoutError(f"took longer than {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _stamp(path: pathlib.Path) -> tuple[int, int] | None:
    """(mtime in ns, size) of a file, None while it is missing (mid-save)."""
    try:
        stat = path.stat()
    except OSError:
        return None
    return stat.st_mtime_ns, stat.st_size
