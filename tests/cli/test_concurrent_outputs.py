"""Several processes writing one output path: exactly one wins, the others say so."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

CONFLICT = "another program wrote this file after this run started; kept theirs, discarded ours"


# simulated seconds per bake: long enough (about 2 s of work) that the bakes overlap even
# when a loaded machine starts the second process a few seconds after the first
SECONDS = "10"


def _bakes(out: Path, writers: int) -> list[subprocess.CompletedProcess[str]]:
    """`writers` real processes baking different seeds of the octopus to `out` at once."""
    processes = [
        subprocess.Popen(
            [sys.executable, "-m", "ecs_tentacles", "bake", "octopus", "--seconds", SECONDS]
            + ["--seed", str(seed), "--out", out.name, "--json", "--quiet"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=out.parent,
        )
        for seed in range(1, writers + 1)
    ]
    results = []
    for process in processes:
        stdout, stderr = process.communicate(timeout=240)
        code = process.returncode
        results.append(subprocess.CompletedProcess(process.args, code, stdout, stderr))
    return results


@pytest.mark.parametrize(("suffix", "writers"), [(".npz", 3), (".glb", 2)])
def test_exactly_one_of_several_concurrent_bakes_wins(
    tmp_path: Path, suffix: str, writers: int
) -> None:
    out = tmp_path / f"same{suffix}"
    results = _bakes(out, writers)
    winners = [r for r in results if r.returncode == 0]
    losers = [r for r in results if r.returncode != 0]
    assert len(winners) == 1, [(r.returncode, r.stderr) for r in results]
    for loser in losers:
        assert loser.returncode == 1
        assert loser.stdout == ""
        errors = [line for line in loser.stderr.splitlines() if line.startswith("error:")]
        assert errors == [f"error: {out.name}: {CONFLICT}"]
    reported = json.loads(winners[0].stdout)["sha256"]
    assert hashlib.sha256(out.read_bytes()).hexdigest() == reported
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary files left
