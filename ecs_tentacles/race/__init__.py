"""Race to the flag: steer your creature to the flag before the rivals crawl there.

A game mode written from the handbook (docs/extending/game-modes.md), as a plugin
(`ecs_tentacles.game`):

    "plugins": {"race": {}},
    "game": {"mode": "race", "level": "1. Sprint", "runner": "you",
             "flag": {"position": [6, 0], "radius": 0.5}, "seconds": 60}

One creature of the scene is the runner, the player's; every other creature is a rival
that crawls straight for the flag. The first mantle inside the flag's ring wins the
race: the runner's and you win, a rival's and you lose; the clock running out loses
too. Rocks and walls stand in the straight line: send the runner round them.

Parts: `rules` (the mode's keys of `game` and its checks), `game` (`RaceGame`, the
resource: the flag, the runner's path, the clock, the outcome, the input log, the
level's start), `entries` (what the plugin adds to the renderer's, sandbox's and game
layer's registries), `hud` (the sandbox's Race section and banner), `play` (driving a
level headless: a player, recorded inputs, replays), `plugin` (`RacePlugin`). Its
systems are in `race/systems/`: `steering` (sends the rivals to the flag and the runner
along its path) and `referee` (the clock, who reached the flag first).
"""
