"""Another reduced model for the tools that study the reduced tier's pace (`--model` of
`tools/reduced_pace.py` and `tools/lod_fidelity.py`): which of its simplifications makes
which part of the gap between a reduced creature and its full self.

    use_model(model_settings("links=1,rate=1,gain=1,damping=1"))  # then build a World

Keys: `links` (reduced links per full link, `physics.reduced_body.LINK_SHARE`, 0.5; 1 keeps
every link), `rate` (full steps per reduced step, `physics.tiers.REDUCED_RATE`, 8; 1 is
the full rate), `gain` and `damping` (`STIFFNESS_GAIN` 0.9 and `DAMPING_GAIN` 1.5; 1 and 1
are the full servos' gains when every link is kept). `use_model` sets them for this
process: the worlds it builds after the call use them.
"""

from __future__ import annotations

from ecs_tentacles.physics import reduced as reduced_model
from ecs_tentacles.physics import reduced_body, tiers

# the keys: (module, constant, the test of a valid value, what that test says)
MODEL_KEYS = {
    "links": (reduced_body, "LINK_SHARE", lambda v: 0.0 < v <= 1.0, "in (0, 1]"),
    "rate": (tiers, "REDUCED_RATE", lambda v: v >= 1 and v == int(v), "an integer >= 1"),
    "gain": (reduced_model, "STIFFNESS_GAIN", lambda v: v > 0.0, "> 0"),
    "damping": (reduced_model, "DAMPING_GAIN", lambda v: v > 0.0, "> 0"),
}
DEFAULT_MODEL = {key: getattr(module, name) for key, (module, name, _, _) in MODEL_KEYS.items()}


def model_settings(text: str) -> dict[str, float]:
    """ "links=1,rate=2" -> {"links": 1.0, "rate": 2.0}; ValueError naming a bad item."""
    out = {}
    for item in text.split(","):
        key, _, value = item.partition("=")
        if key not in MODEL_KEYS:
            raise ValueError(f"keys are {', '.join(MODEL_KEYS)}, got {item!r}")
        try:
            number = float(value)
        except ValueError:
            raise ValueError(f"{key}: a number, got {value!r}") from None
        _, _, valid, says = MODEL_KEYS[key]
        if not valid(number):
            raise ValueError(f"{key}: must be {says}, got {value}")
        out[key] = number
    return out


def use_model(model: dict[str, float] | None) -> None:
    """Set this process's reduced model to `model` (the defaults for the keys it lacks)."""
    for key, (module, name, _, _) in MODEL_KEYS.items():
        value = (model or {}).get(key, DEFAULT_MODEL[key])
        setattr(module, name, int(value) if name == "REDUCED_RATE" else value)
