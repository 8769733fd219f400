"""The world options are declared once and read the same way by every command."""

from __future__ import annotations

import argparse

import pytest

from ecs_tentacles.cli.command import build_parser
from ecs_tentacles.cli.world_options import world_options
from ecs_tentacles.options import WorldOptions

SIMULATING = {"run": [], "play": ["--headless", "--json"], "bake": ["--seconds", "1"]}


def _options_of(command: str) -> dict[str, argparse.Action]:
    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {
        option: action
        for action in commands.choices[command]._actions
        for option in action.option_strings
    }


@pytest.mark.parametrize("command", sorted(SIMULATING))
def test_every_simulating_command_reads_the_same_options(command: str, tmp_path: str) -> None:
    extra = SIMULATING[command]
    if command == "bake":
        extra = [*extra, "--out", f"{tmp_path}/t.npz"]
    argv = [command, "octopus", *extra, "--seed", "4", "--allow-systems", "--threads", "2"]
    args = build_parser().parse_args([*argv, "--lod", "off", "--focus", "-1,2,3"])
    assert world_options(args) == WorldOptions(
        seed=4, allow_systems=True, threads=2, lod=False, focus=(-1.0, 2.0, 3.0)
    )


def test_one_declaration_one_help() -> None:
    helps = {
        command: {name: _options_of(command)[name].help for name in ("--allow-systems",)}
        for command in ("run", "play", "bake", "bench", "systems", "validate")
    }
    assert len({str(h) for h in helps.values()}) == 1, helps
    for name in ("--threads", "--lod", "--focus"):
        assert len({_options_of(c)[name].help for c in ("run", "play", "bake", "bench")}) == 1


def test_options_a_command_lacks_keep_the_scenes() -> None:
    args = build_parser().parse_args(["systems", "octopus"])
    assert world_options(args) == WorldOptions()
