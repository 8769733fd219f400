"""The generic output layers (recorder, take format, exporters, shard planner, `run`)
import no feature package: features reach them through plugin hooks."""

from __future__ import annotations

import grimp
import pytest

FEATURES = ("locomotion", "fur", "threats", "record", "render")
GENERIC = ("export", "distributed", "take", "take.read", "take.tracks", "cli.run", "cli.bake")


@pytest.fixture(scope="module")
def graph() -> grimp.ImportGraph:
    return grimp.build_graph("ecs_tentacles", exclude_type_checking_imports=True)


@pytest.mark.parametrize("generic", GENERIC)
def test_a_generic_output_module_reaches_no_feature(graph: grimp.ImportGraph, generic: str) -> None:
    for feature in FEATURES:
        chain = graph.find_shortest_chains(
            f"ecs_tentacles.{generic}", f"ecs_tentacles.{feature}", as_packages=True
        )
        assert not chain, f"{generic} imports {feature}: {sorted(chain)[0]}"
