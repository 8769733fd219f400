"""Spatial controls: mirrored twins and which control each guide follows (thesis 4.2-4.3).

A control may be mirrored across the creature's x, y or z plane: its twin gets the
mirrored position (and mirrored position keys) and the same behaviour values and
tracks. Each guide follows the control nearest its root, measured between rest
positions in the creature frame (ties go to the control listed first); a guide may
name its control instead.
"""

from __future__ import annotations

import copy
import re
from typing import Any

import numpy as np

AXIS = {"x": 0, "y": 1, "z": 2}
_SIDES = [
    (re.compile(r"^L_"), "R_"),
    (re.compile(r"^R_"), "L_"),
    (re.compile(r"_L$"), "_R"),
    (re.compile(r"_R$"), "_L"),
    (re.compile(r"left"), "right"),
    (re.compile(r"right"), "left"),
    (re.compile(r"Left"), "Right"),
    (re.compile(r"Right"), "Left"),
]


def mirror_name(name: str) -> str:
    """The twin's name: L_/R_ (prefix), _L/_R (suffix) or left/right swapped, else +_mirror."""
    for pattern, other in _SIDES:
        if pattern.search(name):
            return pattern.sub(other, name, count=1)
    return f"{name}_mirror"


def mirror_point(point: list[float] | np.ndarray, axis: str) -> list[float]:
    """`point` reflected across the creature's plane normal to `axis`."""
    mirrored = [float(x) for x in point]
    mirrored[AXIS[axis]] = -mirrored[AXIS[axis]]
    return mirrored


def expand_mirrors(controls: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The controls with every mirrored twin inserted right after its original."""
    result: list[dict[str, object]] = []
    for control in controls:
        result.append(control)
        axis = control.get("mirror", "none")
        if axis == "none":
            continue
        twin = copy.deepcopy(control)
        twin["name"] = mirror_name(control["name"])
        twin["mirror"] = "none"
        twin["position"] = mirror_point(control["position"], axis)
        for track in twin.get("tracks", []):
            if track["attribute"] == "position":
                for key in track["keys"]:
                    key["value"] = mirror_point(key["value"], axis)
        result.append(twin)
    return result


def nearest_control(roots: np.ndarray, controls: np.ndarray) -> np.ndarray:
    """Index of the control (rows of `controls`, (c, 3)) nearest each root ((n, 3))."""
    if len(controls) == 0:
        raise ValueError("a fur needs at least one control")
    best = np.zeros(len(roots), dtype=np.int64)
    best_d = np.full(len(roots), np.inf)
    for index, point in enumerate(controls):  # few controls: one pass over the roots each
        d = np.sum((roots - point) ** 2, axis=1)
        closer = d < best_d
        best[closer] = index
        best_d[closer] = d[closer]
    return best
