"""The render system touches only what it declares (as every built-in system must).

It runs in the sandbox only (`play`), so it is checked here, with a real headless
sandbox, like the others are in `tests/test_declarations.py`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tests.declarations import step_declared


def test_render_reads_only_what_it_declares(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("hedgehog_octopus")
    world = sandbox.world
    assert "render" in world.schedule
    before = sandbox.renderer.current[0].copy()
    step_declared(world, 20)
    assert (sandbox.renderer.current[0] != before).any()  # it handed over the new poses
