"""Takes are untrusted input: every hand-broken take is refused with one line, exit 2."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.take import Take, TakeError
from ecs_tentacles.take.read import read_take
from tests.export.broken_takes import BROKEN_TAKES


@pytest.fixture(scope="module")
def good_take(tmp_path_factory: pytest.TempPathFactory, guided_take: Take) -> Path:
    path = tmp_path_factory.mktemp("good") / "good.npz"
    guided_take.save(path)
    return path


def test_the_corpus_is_large_and_starts_from_a_sound_take(good_take: Path) -> None:
    assert len(BROKEN_TAKES) >= 30
    header, arrays = read_take(good_take)
    assert header["guides"] is not None and set(arrays) >= {"pos", "guide_points"}


@pytest.mark.parametrize("case", sorted(BROKEN_TAKES))
def test_export_refuses_every_broken_take_with_one_line(
    case: str, good_take: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / f"{case}.npz"
    BROKEN_TAKES[case](good_take, bad)
    out = tmp_path / "out"
    out.mkdir()
    suffix = ".glb" if sorted(BROKEN_TAKES).index(case) % 2 else ".usda"
    assert main(["export", str(bad), "--out", str(out / f"x{suffix}"), "--quiet"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {bad}: "), captured.err
    assert captured.out == "" and list(out.iterdir()) == []


def test_a_real_zip_bomb_is_refused_before_it_is_inflated(tmp_path: Path) -> None:
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        with archive.open("pos.npy", "w", force_zip64=True) as entry:
            np.lib.format.write_array_header_2_0(
                entry, {"descr": "<f4", "fortran_order": False, "shape": (64, 1024, 1024)}
            )
            block = bytes(1 << 20)
            for _ in range(256):
                entry.write(block)
    assert bomb.stat().st_size < 1 << 20  # 256 MiB of zeros in well under 1 MiB
    with pytest.raises(TakeError, match="would expand to 268435"):
        Take.load(bomb, max_bytes=64 << 20)


@pytest.mark.parametrize("suffix", [".glb", ".usda", ".usdc"])
def test_exporters_refuse_a_recorded_take_with_non_finite_numbers(
    suffix: str, guided_take: Take, tmp_path: Path
) -> None:
    from dataclasses import replace

    from ecs_tentacles.export import write

    pos = guided_take.pos.copy()
    pos[2, 3, 1] = np.nan
    broken = replace(guided_take, pos=pos)
    target = tmp_path / f"take{suffix}"
    with pytest.raises(TakeError) as caught:
        write(broken, target)
    assert str(caught.value) == (
        f"{target}: cannot export this take: pos: non-finite value nan at (2, 3, 1)"
    )
    assert list(tmp_path.iterdir()) == []


def test_a_take_without_goals_loads(tmp_path: Path) -> None:
    """Empty arrays (no goals, no suckers held) read back; they once failed to load."""
    out = tmp_path / "hedgehog.npz"
    assert main(["bake", "hedgehog_octopus", "--seconds", "0.1", "--out", str(out), "--quiet"]) == 0
    take = Take.load(out)
    assert take.tracks["goal_pos"].shape == (0, 3)
    assert take.tracks["goal_active"].shape == (take.frames, 0)


def test_loading_a_large_take_costs_about_its_size_once(good_take: Path, tmp_path: Path) -> None:
    import json
    import tracemalloc

    from ecs_tentacles.take import write_npz
    from tests.export.broken_takes import _read

    header, arrays = _read(good_take)  # version 1's layout: read whole
    frames = header["frames"]
    repeat = -(-(40 * 1024**2) // arrays["pos"].nbytes)  # about 40 MB of poses and more
    for name, array in arrays.items():
        if name != "header" and array.ndim and len(array) == frames:
            arrays[name] = np.concatenate([array] * repeat)
    header["frames"] = frames * repeat
    arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    big = tmp_path / "big.npz"
    write_npz(big, arrays)
    raw = sum(a.nbytes for n, a in arrays.items() if n != "header")
    del arrays
    tracemalloc.start()
    try:
        _, loaded = read_take(big)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert sum(a.nbytes for a in loaded.values()) >= raw
    assert peak < 1.05 * raw + 32 * 1024**2, f"peak {peak / 1e6:.0f} MB for {raw / 1e6:.0f} MB"


HOSTILE_HEADERS = {  # header edit -> the one line `export` says after the file's name
    "a 400-digit frame rate": (
        lambda header: header.update(fps=10**399),
        "header.fps: a number of 400 characters, at most 100",
    ),
    "a 400-digit radius": (
        lambda header: header["body_plans"]["plans"][0]["bodies"][1].update(radius=-(10**399)),
        "header.body_plans.plans[0].bodies[1].radius: a number of 401 characters, at most 100",
    ),
    "a key nested 500 deep": (
        lambda header: header.update(notes=_nested(500)),
        "header: nested deeper than 64 levels",
    ),
    "a key nested 100000 deep": (
        lambda header: header.update(notes=_nested(100_000)),
        "header: nested deeper than 64 levels",
    ),
}


def _nested(depth: int) -> str:
    return "@" * depth  # replaced by `depth` nested arrays once the header is JSON text


@pytest.mark.parametrize("case", sorted(HOSTILE_HEADERS))
def test_a_header_with_a_huge_number_or_deep_nesting_is_exit_2_naming_where(
    case: str, good_take: Path, tmp_path: Path
) -> None:
    """In a real `export`: the 400-digit numbers failed with OverflowError (exit 1)."""
    import json
    import re
    import subprocess
    import sys

    from ecs_tentacles.take import write_npz

    with np.load(good_take) as npz:
        arrays = {name: npz[name] for name in npz.files}
    header = json.loads(arrays["header"].tobytes())
    change, said = HOSTILE_HEADERS[case]
    change(header)
    text = re.sub(r'"(@+)"', lambda m: "[" * len(m[1]) + "]" * len(m[1]), json.dumps(header))
    arrays["header"] = np.frombuffer(text.encode(), np.uint8)
    bad = tmp_path / "bad.npz"
    write_npz(bad, arrays)
    out = tmp_path / "out.usda"
    done = subprocess.run(
        [sys.executable, "-P", "-m", "ecs_tentacles", "export", str(bad), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (done.returncode, done.stderr) == (2, f"error: {bad}: {said}\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.npz"]
