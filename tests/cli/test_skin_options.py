"""`export`/`bake` write skinned creatures by default; `--rigid`, `--keys`, detail flags."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.gltf import read_glb
from ecs_tentacles.take import Take


@pytest.fixture
def take_file(octopus_take: Take, tmp_path: Path) -> Path:
    path = tmp_path / "take.npz"
    octopus_take.save(path)
    return path


def test_export_is_skinned_unless_rigid(
    take_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    skinned, rigid = tmp_path / "skinned.glb", tmp_path / "rigid.glb"
    assert main(["export", str(take_file), "--out", str(skinned), "--quiet"]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    size = skinned.stat().st_size
    assert line == (
        f"{skinned}: skinned, {size} bytes, {121 * 82} keys (every frame: nothing reduced;"
        " --keys reduced keeps fewer)"
    )
    document, _ = read_glb(skinned.read_bytes())
    assert len(document["skins"]) == 1 and len(document["skins"][0]["joints"]) == 81
    assert main(["export", str(take_file), "--out", str(rigid), "--rigid", "--quiet"]) == 0
    assert "skins" not in read_glb(rigid.read_bytes())[0]


def test_reduced_keys_are_reported(
    take_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "octopus.usdc"
    argv = ["export", str(take_file), "--out", str(out), "--quiet"]
    assert main([*argv, "--keys", "reduced", "--key-tolerance", "0.5"]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    found = re.search(r"keys (\d+) -> (\d+) .* max error ([\d.]+) deg", line)
    assert found is not None, line
    before, after, error = int(found[1]), int(found[2]), float(found[3])
    assert before == 121 * 82 and after < before // 2 and error <= 0.5


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--sides", "10"], "argument --sides: must be a multiple of 4 and >= 4, got 10"),
        (
            ["--rings-per-link", "0"],
            "argument --rings-per-link: must be >= 1, got 0 (see ecs-tentacles export --help)",
        ),
        (["--key-tolerance", "0"], "argument --key-tolerance: must be > 0 degrees, got 0.0"),
    ],
)
def test_bad_skin_flags_exit_2_with_one_line(
    take_file: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    flags: list[str],
    message: str,
) -> None:
    argv = ["export", str(take_file), "--out", str(tmp_path / "a.glb"), *flags]
    try:
        code = main(argv)
    except SystemExit as stop:  # refused while reading the arguments
        code = int(stop.code or 0)
    assert code == 2
    assert capsys.readouterr().err == f"error: {message}\n"
    assert not (tmp_path / "a.glb").exists()
