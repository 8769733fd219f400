"""The mesh cache is read as untrusted files (`ecs_tentacles.terrain.mesh_cache`): an
entry that is damaged, not a regular file, too big, degenerate, another mesh's or a
forged one is ignored, the mesh decomposed again and the entry written afresh; none of
them stops, blocks or swells `validate`.

Real processes (`python -P -m ecs_tentacles validate`, each with its own memory of
meshes) over real files, in a cache folder of the test's own (`XDG_CACHE_HOME`).
"""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from ecs_tentacles.terrain import mesh_cache
from tests.terrain.test_bounded_inputs import arch

ROCK_SIDE = 0.5  # metres: a convex box, split without CoACD (fast)


def box_obj(side: float) -> str:
    h = side / 2
    corners = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [
        (1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2),
        (3, 4, 8), (3, 8, 7), (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4),
    ]  # fmt: skip
    lines = [f"v {x} {y} {z}" for x, y, z in corners] + [f"f {a} {b} {c}" for a, b, c in faces]
    return "\n".join(lines) + "\n"


def rock_scene(folder: pathlib.Path, side: float = ROCK_SIDE) -> pathlib.Path:
    """A scene of one creature at the origin and one mesh rock 4 m away."""
    folder.mkdir(exist_ok=True)
    (folder / "rock.obj").write_text(box_obj(side))
    rock = {"shape": "mesh", "file": "rock.obj", "position": [4, 0, 0]}
    scene = {
        "version": 1,
        "terrain": {"obstacles": [rock]},
        "creatures": [{"name": "c0", "position": [0, 0]}],
    }
    path = folder / "scene.json"
    path.write_text(json.dumps(scene))
    return path


def validate(
    scene: pathlib.Path, cache: pathlib.Path, *, python: list[str] | None = None
) -> subprocess.CompletedProcess[str]:
    """`validate` in a process of its own, `cache` its XDG_CACHE_HOME."""
    command = python or [sys.executable, "-P", "-m", "ecs_tentacles"]
    try:
        return subprocess.run(
            [*command, "validate", str(scene)],
            env={**os.environ, "XDG_CACHE_HOME": str(cache)},
            capture_output=True,
            text=True,
            timeout=120,
        )
    except subprocess.TimeoutExpired:  # the old way with a FIFO entry: forever
        raise AssertionError("validate did not end in 120 s") from None


def entries(cache: pathlib.Path) -> list[pathlib.Path]:
    folder = cache / "ecs_tentacles" / "meshes"
    return sorted(folder.iterdir()) if folder.is_dir() else []


@pytest.fixture(scope="module")
def validated_once(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    """A folder holding the rock's scene (`scene/`) validated once (`cache/`)."""
    folder = tmp_path_factory.mktemp("validated")
    done = validate(rock_scene(folder / "scene"), folder / "cache")
    assert done.returncode == 0, done.stderr
    return folder


# a cached rock: (scene, cache folder, its one entry, the entry's bytes)
Cached = tuple[pathlib.Path, pathlib.Path, pathlib.Path, bytes]


@pytest.fixture
def cached(validated_once: pathlib.Path, tmp_path: pathlib.Path) -> Cached:
    """A copy of the validated rock: (scene, cache, its one entry, the entry's bytes)."""
    for name in ("scene", "cache"):
        shutil.copytree(validated_once / name, tmp_path / name)
    [entry] = entries(tmp_path / "cache")
    return tmp_path / "scene" / "scene.json", tmp_path / "cache", entry, entry.read_bytes()


def assert_decomposed_again(
    scene: pathlib.Path, cache: pathlib.Path, entry: pathlib.Path, good: bytes
) -> None:
    """`validate` says ok, and the entry is the rock's own again (a regular file)."""
    done = validate(scene, cache)
    assert (done.returncode, done.stderr) == (0, ""), done.stderr
    assert "ok" in done.stdout
    assert entries(cache) == [entry]  # no temporary file left either
    assert entry.is_file() and not entry.is_symlink()
    assert entry.read_bytes() == good


@pytest.mark.parametrize("mesh", ["a box", "an arch"])
def test_a_good_entry_is_used_by_the_next_process(
    request: pytest.FixtureRequest, tmp_path: pathlib.Path, mesh: str
) -> None:
    """The checks pass what the decomposition wrote (an arch's CoACD pieces reach a
    little past its box): the next run reads the entry, no decomposition rewrites it.
    The box's first run is the module's (`validated_once`)."""
    if mesh == "a box":
        scene, cache, entry, _ = request.getfixturevalue("cached")
    else:
        scene, cache = rock_scene(tmp_path / "scene"), tmp_path / "cache"
        arch(scene.parent / "rock.obj")
        assert validate(scene, cache).returncode == 0
        [entry] = entries(cache)
    before = entry.stat()
    done = validate(scene, cache)
    assert (done.returncode, done.stderr) == (0, "")
    after = entry.stat()
    assert (after.st_ino, after.st_mtime_ns) == (before.st_ino, before.st_mtime_ns)


@pytest.mark.parametrize("damage", ["truncated", "one byte changed", "empty"])
def test_a_damaged_entry_is_ignored_and_written_again(cached: Cached, damage: str) -> None:
    """A truncated entry failed every run (`error: run: BadZipFile`, naming no file)
    until deleted by hand."""
    scene, cache, entry, good = cached
    if damage == "truncated":
        entry.write_bytes(good[: len(good) // 2])
    elif damage == "one byte changed":
        middle = len(good) // 2
        entry.write_bytes(good[:middle] + bytes([good[middle] ^ 0x40]) + good[middle + 1 :])
    else:
        entry.write_bytes(b"")
    assert_decomposed_again(scene, cache, entry, good)


@pytest.mark.parametrize("kind", ["FIFO", "symlink to a FIFO", "symlink to the entry"])
def test_an_entry_that_is_not_a_regular_file_is_never_read(
    cached: Cached, tmp_path: pathlib.Path, kind: str
) -> None:
    """A FIFO in the cache blocked `validate` forever (and kept its first SIGTERM)."""
    scene, cache, entry, good = cached
    entry.unlink()
    if kind == "FIFO":
        os.mkfifo(entry)
    elif kind == "symlink to a FIFO":
        os.mkfifo(tmp_path / "pipe")
        entry.symlink_to(tmp_path / "pipe")
    else:  # even a good one: the cache's entries are files, never links to elsewhere
        (tmp_path / "elsewhere").write_bytes(good)
        entry.symlink_to(tmp_path / "elsewhere")
    assert_decomposed_again(scene, cache, entry, good)


def zip_bomb(path: pathlib.Path, megabytes: int) -> None:
    """An .npz of about 1/1000 of `megabytes` on disk: float64 zeros, deflated."""
    rows = megabytes * 2**20 // 24
    header = {"descr": "<f8", "fortran_order": False, "shape": (rows, 3)}
    zeros = bytes(2**20)
    with (
        zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as archive,
        archive.open("arr_0.npy", "w", force_zip64=True) as member,
    ):
        np.lib.format.write_array_header_1_0(member, header)
        for _ in range(megabytes):
            member.write(zeros)


PEAK = """
import resource, sys
from ecs_tentacles.cli import main
code = main(sys.argv[1:])
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024, file=sys.stderr)
sys.exit(code)
"""


def test_a_big_entry_costs_the_main_process_nothing(
    cached: Cached,
) -> None:
    """A 2.9 MB entry took 8.9 GB and 97 s in the main process, outside the mesh budget.
    Here a 0.6 MB one that decompresses to 600 MB: the main process's peak memory is
    what it is with a good entry (this one is not read at all: larger than any entry)."""
    scene, cache, entry, good = cached
    python = [sys.executable, "-P", "-c", PEAK]
    clean = validate(scene, cache, python=python)
    assert clean.returncode == 0, clean.stderr
    zip_bomb(entry, 600)
    assert entry.stat().st_size > mesh_cache.MAX_ENTRY_BYTES
    bombed = validate(scene, cache, python=python)
    assert bombed.returncode == 0, bombed.stderr
    peaks = [int(done.stderr.split()[-1]) for done in (clean, bombed)]
    assert peaks[1] < peaks[0] + 100, f"peak resident MB with a good entry, a bomb: {peaks}"
    assert entry.read_bytes() == good


def forged(kind: str, side: float) -> tuple[np.ndarray, ...]:
    h = side / 2
    if kind == "a flat piece":  # a square inside the rock: no volume
        return (np.array([[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]]),)
    # a tetrahedron of about a kilometre, every vertex within the 1000 m bound of any
    # mesh; around the creature at the origin (4 m from the rock's own origin)
    return (np.array([[-600.0, -600, -10], [600, -600, -10], [0, 600, -10], [0, 0, 800]]),)


@pytest.mark.parametrize("kind", ["a flat piece", "a 1 km tetrahedron", "another mesh's entry"])
def test_an_entry_that_is_not_the_meshs_pieces_is_replaced(
    cached: Cached, tmp_path: pathlib.Path, kind: str
) -> None:
    """Entries that pass every check of their own format: a degenerate piece made the
    good rock refused on every run; a 1 km tetrahedron replaced the 0.5 m rock (the
    creature then inside it); a smaller rock's entry under this rock's name replaced it
    silently. Each is ignored: the rock decomposed again, its entry written afresh."""
    scene, cache, entry, good = cached
    if kind == "another mesh's entry":
        other_cache = tmp_path / "other cache"
        done = validate(rock_scene(tmp_path / "other", side=0.3), other_cache)
        assert done.returncode == 0, done.stderr
        [other] = entries(other_cache)
        entry.write_bytes(other.read_bytes())
    else:  # laid out as this package lays its entries out: their digests check
        entry.write_bytes(mesh_cache.encode(entry.stem, forged(kind, ROCK_SIDE)))
        assert entry.read_bytes() != good
    assert_decomposed_again(scene, cache, entry, good)


def test_a_good_entry_is_read_back_as_it_was_kept(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    key = "ab" * 32
    pieces = (np.arange(12.0).reshape(4, 3) ** 1.5, np.eye(4, 3) * 2 - 0.5)
    mesh_cache.keep(key, pieces)
    back = mesh_cache.read(key)
    assert back is not None and len(back) == 2
    for got, want in zip(back, pieces, strict=True):
        np.testing.assert_array_equal(got, want)
    assert mesh_cache.read("cd" * 32) is None  # absent
