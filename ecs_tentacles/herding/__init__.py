"""The herding game: drive creatures through a gate into a pen with a predator in time.

A game mode written as a plugin, reaching the engine only through the plugin API:

    "plugins": {"herding": {}},
    "game": {"mode": "herding", "pen": {"centre": [3, 0], "radius": 1.2,
                                        "gate": {"heading_deg": 180, "width": 1.6}},
             "need": 4, "seconds": 60, "par": 40, "predator": {"position": [-3, 0]}}

Parts: `schema` (the scene's `game` key), `game` (`HerdingGame`, the resource: the
pen, the predator, the clock, the score, the input log and the level's start),
`events` (`CreaturePenned`, `CreatureLeft`, `GameWon`, `GameLost`), `fence` (the pen's
fence and gate: solid in physics, respected by every goal), `open_ground` (where a
creature may be sent: off walls, through the gate only), `predator_body` (the predator
as drawn), `levels` (the levels in order, par times, stars, which are open),
`best_times` (the best-times file in the user's data folder), `hud` and `hud_levels`
(the sandbox's game section, level select and banner), `entries` (what the plugin adds
to the renderer's, take's and report's registries), `play` (driving a level headless:
the bot and replays), `plugin` (`HerdingPlugin`: what it adds to the registries). Its
systems are in `herding/systems/`: `predator` (moves the predator toward where the
player aims it, walking or running on its stamina), `herd` (the creatures flee it,
graze and keep together) and `referee` (pens, clock, win and lose).
"""
