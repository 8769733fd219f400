"""The game's levels in order: which are unlocked, their par times and stars, the next one.

    levels()                       # [Level, ...]: every bundled scene with a `game`, in order
    next_level("herding_1_field")  # "herding_2_shore" (None after the last of its mode)
    level.stars                    # 0-3: the stars its best time earns (0: never won)

A level is a bundled scene (`assets/scenes/`) with a `game` key; the levels of one mode
go in the order of their scene names (`herding_1_field`, `herding_2_shore`, ...). The
first level of a mode is always open; each next one opens once the one before it is won
(it has a best time), in the modes whose wins the best-times file keeps (`RECORDED`:
the herding game's section writes them); a mode that keeps none has every level open.
Stars come from the best time against the level's `par`: 3 within
par, 2 within 1.5x par, 1 for any win (`ecs_tentacles.herding.game.stars_for`). The best
times are the best-times file's (`ecs_tentacles.herding.best_times`, keyed by the level's
name as the game shows it); nothing here writes.

Reads: the bundled scenes' `game` keys, the best-times file. Writes: nothing.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

from ecs_tentacles.herding import best_times
from ecs_tentacles.herding.game import stars_for
from ecs_tentacles.scene.load import bundled_scene, bundled_scene_names

RECORDED = ("herding",)  # the modes whose wins are written to the best-times file


@dataclass(frozen=True)
class Level:
    """One level as the level select and `ecs-tentacles levels` show it."""

    scene: str  # the bundled scene's name: what `play` opens
    title: str  # the level's name in the game (and the best-times file's key)
    mode: str
    creatures: int
    need: int
    seconds: float
    par: float
    best: float | None  # seconds: the best win, None: never won
    stars: int
    unlocked: bool

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


def _game(name: str) -> Mapping[str, Any] | None:
    """The bundled scene's `game` key (None: not a level, or not a readable scene)."""
    try:
        data = json.loads(bundled_scene(name).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    game = data.get("game") if isinstance(data, dict) else None
    if not isinstance(game, dict) or not isinstance(game.get("mode"), str):
        return None
    return {**game, "creatures": len(data.get("creatures") or []), "scene": name}


def levels(times: Mapping[str, float] | None = None) -> list[Level]:
    """Every bundled level, grouped by mode, each mode's in scene-name order, with its
    best time and stars from `times` (default: the best-times file)."""
    if times is None:
        try:
            times = best_times.best_times()
        except OSError:  # an unreadable data folder: no times
            times = {}
    games = [g for g in (_game(name) for name in bundled_scene_names()) if g is not None]
    out: list[Level] = []
    for mode in dict.fromkeys(g["mode"] for g in games):
        previous_won = True
        for game in (g for g in games if g["mode"] == mode):
            title = str(game.get("level") or game["scene"])
            seconds = float(game["seconds"])
            par = float(game.get("par") or 0.5 * seconds)
            best = times.get(title)
            out.append(
                Level(
                    scene=game["scene"],
                    title=title,
                    mode=mode,
                    creatures=int(game["creatures"]),
                    need=int(game.get("need", 0)),
                    seconds=seconds,
                    par=par,
                    best=best,
                    stars=stars_for(best, par) if best is not None else 0,
                    unlocked=previous_won or mode not in RECORDED,
                )
            )
            previous_won = best is not None
    return out


def next_level(scene: str, found: list[Level] | None = None) -> Level | None:
    """The level after bundled scene `scene` in its mode (None: the last, or not a level)."""
    found = levels() if found is None else found
    names = [level.scene for level in found]
    if scene not in names:
        return None
    here = found[names.index(scene)]
    after = [level for level in found[names.index(scene) + 1 :] if level.mode == here.mode]
    return after[0] if after else None


def stars_text(stars: int) -> str:
    """Stars as the HUD and the listing show them: `***`, `**-`, `*--`, `---`."""
    return "*" * stars + "-" * (3 - stars)
