"""tools/reduced_models.py: `--model` text is checked key by key, and the model it names is
the one the worlds built afterwards step, until the defaults are asked for again."""

from __future__ import annotations

from collections.abc import Iterator
from types import ModuleType

import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.physics import reduced_body, tiers
from ecs_tentacles.world import World
from tests.tools.loader import TOOLS, load_tool

TOOL = TOOLS / "reduced_models.py"


@pytest.fixture(scope="module")
def tool() -> Iterator[ModuleType]:
    """The tool, imported once (its defaults are what the library holds at import), and
    the library's reduced model as it was afterwards, whatever a test did."""
    if not TOOL.is_file():
        pytest.skip("needs the source tree")
    module = load_tool("reduced_models")
    yield module
    module.use_model(None)


def _reduced_links(tool: ModuleType, model: dict[str, float] | None) -> tuple[int, int]:
    """(joints less the root, steps a frame) of a crowd's reduced model under `model`."""
    tool.use_model(model)
    scene = crowd_scene(2, seed=0, uniform=True)
    scene["physics"] = {"lod": {"full": 0, "reduced": 2}}
    with World.from_scene(scene) as world:
        world.step(1)
        batch = world.physics.batches[0]
        assert batch.reduced is not None
        hinges = batch.reduced.model.njnt - 1  # less the root
        return hinges, tiers.reduced_substeps(world.settings.substeps)


def test_model_text_is_read_and_a_bad_item_named(tool: ModuleType) -> None:
    assert tool.model_settings("links=1,rate=1,gain=1,damping=1") == {
        "links": 1.0, "rate": 1.0, "gain": 1.0, "damping": 1.0,
    }  # fmt: skip
    bad_items = {
        "links=2": "links: must be in",
        "links=0": "links: must be in",
        "rate=0.5": "rate: must be an integer",
        "size=1": "'size=1'",
        "gain=x": "gain: a number",
        "damping=-1": "damping: must be > 0",
    }
    for bad, says in bad_items.items():
        with pytest.raises(ValueError, match=says):
            tool.model_settings(bad)


def test_the_model_set_is_the_one_worlds_step_until_the_defaults_come_back(
    tool: ModuleType,
) -> None:
    default_hinges, default_steps = _reduced_links(tool, None)
    every_hinges, every_steps = _reduced_links(tool, {"links": 1.0, "rate": 2.0})
    assert every_hinges == 2 * default_hinges  # the default octopus: 10 links, then 5
    assert (default_steps, every_steps) == (1, 4)  # 480 Hz scene: 60 Hz, then 240 Hz
    assert _reduced_links(tool, None) == (default_hinges, default_steps)
    assert (reduced_body.LINK_SHARE, tiers.REDUCED_RATE) == (0.5, 8)
