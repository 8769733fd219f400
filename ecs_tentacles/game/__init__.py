"""The game layer: game modes as a registry, the scene's `game` key, and a game's result.

A scene that is a level names its mode, and the mode's rules beside it:

    "plugins": {"race": {}},
    "game": {"mode": "race", "level": "1. Sprint", "flag": {"position": [4, 0]}, ...}

A plugin registers a mode in `build(app)`: `app.add(GameModes, GameMode(name, schema,
result))` (`modes`). The layer owns the `game` key (the `game` plugin, turned on with
any plugin that `requires` it): `game.mode` must name a mode a plugin on registered,
and the rest of `game` is checked against that mode's schema and its `problems`
(`rules`). `run` and `play --headless` ask the mode for its `GameResult` and stop once
the game is won or lost (`rules.result`).

Parts: `modes` (`GameMode`, `GameModes`, `GameResult`: pure data, what a mode imports),
`rules` (checking `game`, its defaults, the world's mode and result), `plugin`
(`GamePlugin`: the `game` key and its check).
"""
