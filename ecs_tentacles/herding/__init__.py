"""The herding game: drive creatures into a pen with a predator before the time runs out.

A game mode written as a plugin, reaching the engine only through the plugin API:

    "plugins": {"flee": {}, "herding": {}},
    "game": {"mode": "herding", "pen": {"centre": [3, 0], "radius": 1.2},
             "need": 4, "seconds": 60, "predator": {"position": [-3, 0]}}

Parts: `schema` (the scene's `game` key), `game` (`HerdingGame`, the resource: the
pen, the predator, the clock, the score, the input log and the level's start),
`events` (`CreaturePenned`, `GameWon`, `GameLost`), `best_times` (the best-times file
in the user's data folder), `hud` (the sandbox's game panel and banner), `entries` (what
the plugin adds to the renderer's, take's and report's registries), `play`
(driving a level headless: the bot and replays), `plugin` (`HerdingPlugin`: what it
adds to the registries). Its systems are in `systems/herding/`: `predator` (moves the
predator toward where the player aims it) and `referee` (pens, clock, win and lose).
"""
