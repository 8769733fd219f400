"""Scenes generated from the scene schema build a finite world or are refused cleanly.

hypothesis-jsonschema draws creatures, physics settings and threats from
`scene.schema.json` itself (60 scenes, the same each run: the seeded profile of
tests/conftest.py; the scenes it found before are always tried first), so every
numeric range of the schema is covered; only the
counts are clamped afterwards (a few tentacles, links, guides) to keep each example
small, and the few cross-field rules the validator adds (override indices, fur control
names, increasing key times) are kept so that most examples reach the build. Each
scene goes through `ecs-tentacles validate` and `run` in-process
(`ecs_tentacles.cli.main`): a refused scene exits 2 with one `error:` line per
problem and no traceback; an accepted one builds a world whose bodies, joint targets
and fur curves stay finite for 60 frames without a single MuJoCo warning (instability,
NaN, bad controls) or recovery.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import logging
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from hypothesis_jsonschema import from_schema

from ecs_tentacles.cli import main
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.scene.schema import load_schema
from ecs_tentacles.world import World

FRAMES = 60
SCHEMA = load_schema()
DEFS = SCHEMA["$defs"]


def _of(schema: dict[str, Any]) -> st.SearchStrategy[Any]:
    # a deep copy: hypothesis-jsonschema resolves references in the dicts it is given,
    # and the loader's cached schema must stay as it is
    return from_schema(copy.deepcopy({**schema, "$defs": DEFS}))


def _keys(keys: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """At most three keys, in strictly increasing time (a rule the schema cannot say)."""
    kept: list[dict[str, Any]] = []
    for key in sorted(keys, key=lambda k: k["time"])[:3]:
        if not kept or key["time"] > kept[-1]["time"]:
            kept.append(key)
    return kept


def _tidy_fur(fur: dict[str, Any]) -> None:
    groom = fur.setdefault("groom", {})
    groom.pop("density", None)
    groom["count"] = min(groom.get("count", 200), 12)
    groom["points"] = min(groom.get("points", 8), 4)
    fur["children"] = min(fur.get("children", 0), 1)
    fur["guides"] = fur.get("guides", [])[:2]
    for guide in fur["guides"]:
        guide.pop("control", None)  # a control it names must exist
        guide["points"] = guide["points"][:4]
    if "controls" in fur:
        fur["controls"] = fur["controls"][:2]
        for c, control in enumerate(fur["controls"]):
            control["name"], control["mirror"] = f"c{c}", "none"  # names must not clash
            for track in control.get("tracks", [])[:1]:
                track["keys"] = _keys(track["keys"])
                for key in track["keys"]:  # a position is 3 numbers, the others 0..1
                    value = key["value"]
                    if track["attribute"] == "position":
                        key["value"] = (
                            ([*value, 0, 0, 0][:3]) if isinstance(value, list) else [0, 0, 0]
                        )
                    else:
                        key["value"] = min(max(value, 0), 1) if not isinstance(value, list) else 0.5
            control["tracks"] = control.get("tracks", [])[:1]


def _tidy(creature: dict[str, Any]) -> dict[str, Any]:
    """Fewer tentacles, links, goals and guides, and the cross-field rules the schema
    cannot express kept (override indices, fur names, key order); every other value is
    left as drawn."""
    creature.pop("name", None)  # default names are unique
    tentacles = creature.get("tentacles", {})
    count = min(tentacles.get("count", 8), 3)
    tentacles["count"] = count
    tentacles["links"] = min(tentacles.get("links", 10), 4)
    overrides = {}
    for override in tentacles.get("overrides", []):
        override["index"] %= count
        if "links" in override:
            override["links"] = min(override["links"], 4)
        overrides.setdefault(override["index"], override)
    tentacles["overrides"] = list(overrides.values())[:2]
    creature["tentacles"] = tentacles
    creature["goals"] = creature.get("goals", [])[:2]
    if "fur" in creature:
        _tidy_fur(creature["fur"])
    return creature


def _tidy_threat(threat: dict[str, Any]) -> dict[str, Any]:
    threat["path"] = _keys(threat["path"])
    return threat


def scenes() -> st.SearchStrategy[dict[str, Any]]:
    """Schema-drawn scenes of one or two small creatures and at most one threat."""
    return st.fixed_dictionaries(
        {
            "version": st.just(1),
            "seed": _of(SCHEMA["properties"]["seed"]),
            "physics": _of(SCHEMA["properties"]["physics"]),
            "creatures": st.lists(_of(DEFS["creature"]).map(_tidy), min_size=1, max_size=2),
            "threats": st.lists(_of(DEFS["threat"]).map(_tidy_threat), max_size=1),
        }
    )


@pytest.fixture(scope="module", autouse=True)
def _strategies_built_once() -> Iterator[None]:
    """hypothesis-jsonschema builds an object's property strategy afresh from its schema
    each time it draws that property (canonicalising the schema again), which was more
    than half this module's time: the same schema object gives the same strategy, so it
    is built once here. The scenes drawn are the same ones, in the same order."""
    from hypothesis_jsonschema import _from_schema

    build = getattr(_from_schema, "__from_schema")
    built: dict[tuple[int, int, int], tuple[object, ...]] = {}

    def once(schema: Any, *, alphabet: Any, custom_formats: Any) -> Any:
        key = (id(schema), id(alphabet), id(custom_formats))
        if key not in built:  # the inputs are kept too: their ids stay theirs
            strategy = build(schema, alphabet=alphabet, custom_formats=custom_formats)
            built[key] = (schema, alphabet, custom_formats, strategy)
        return built[key][-1]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(_from_schema, "__from_schema", once)
        yield


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("generated") / "scene.json"


class _Collect(logging.Handler):
    def __init__(self, seen: list[str]) -> None:
        super().__init__(logging.WARNING)
        self.seen = seen

    def emit(self, record: logging.LogRecord) -> None:
        self.seen.append(record.getMessage())


@contextlib.contextmanager
def mujoco_warnings() -> Iterator[list[str]]:
    """Collect MuJoCo's warnings while the block runs, however the physics routes them.

    Our own handler gets them unless the physics layer installs its own, which sends
    them to the `ecs_tentacles.mujoco` logger: that logger is listened to as well.
    """
    seen: list[str] = []
    logger = logging.getLogger("ecs_tentacles.mujoco")
    collect = _Collect(seen)
    logger.addHandler(collect)
    mujoco.set_mju_user_warning(seen.append)
    try:
        yield seen
    finally:
        logger.removeHandler(collect)
        mujoco.set_mju_user_warning(None)


def _cli(*args: str) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(list(args))
    return code, err.getvalue()


def _one(tentacles: dict[str, Any], **creature: Any) -> dict[str, Any]:
    """A scene of one small creature crawling to a goal 1 m ahead."""
    entry = {"position": [0, 0], "goals": [{"position": [1, 0]}], **creature}
    return {
        "version": 1,
        "creatures": [{**entry, "tentacles": {"count": 3, "links": 4, **tentacles}}],
    }


# Scenes this test found before the schema had floors (each builds a world that fails
# within 10 frames if its floor goes): a wave phase divided by 5e-324 (NaN targets),
# an empty force range (MuJoCo refuses the model), a stroke's pace of 0 (5e-324 x 5e-324).
@example(scene=_one({"wavelength": 5e-324}))
@example(scene=_one({"max_torque": 5e-324}))
@example(scene=_one({"speed": 5e-324}, locomotion={"speed": 5e-324}))
@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(scene=scenes())
def test_a_schema_scene_builds_a_finite_world_or_is_refused(
    scene: dict[str, Any], scene_file: Path
) -> None:
    scene_file.write_text(json.dumps(scene))
    code, err = _cli("validate", str(scene_file))
    if code == 2:
        lines = err.splitlines()
        assert lines and all(line.startswith(f"error: {scene_file}: ") for line in lines), err
        assert _cli("run", str(scene_file), "--frames", "1", "--quiet") == (2, err)
        return
    assert code == 0, err
    with mujoco_warnings() as warnings:
        world = World.from_scene(scene_file)
        for _ in range(FRAMES // 10):
            world.step(10)
            assert np.isfinite(world.transforms.pos).all(), f"frame {world.frame}"
            assert np.isfinite(world.transforms.quat).all(), f"frame {world.frame}"
            assert np.isfinite(world.resource(FurData).curves).all(), f"frame {world.frame}"
            assert np.isfinite(world.motors.target).all(), f"frame {world.frame}"
    assert warnings == []  # MuJoCo never blew up
    # steep, strong gravity can make a creature tumble faster than the health check's
    # max_speed: that is recovered and reported, never hidden
    health = world.physics.health
    assert world.events.counts["creature_recovered"] == health.recoveries
    assert world.events.counts["creature_frozen"] == health.frozen
    assert set(health.causes) <= {"speed", "penetration"}
