"""The mesh cache is read as untrusted files (`ecs_tentacles.terrain.mesh_cache`): an
entry that is damaged, not a regular file, too big, degenerate, another mesh's or a
forged one is ignored, the mesh decomposed again and the entry written afresh; none of
them stops, blocks or swells `validate`.

Real processes (`python -P -m ecs_tentacles validate`, each with its own memory of
meshes) over real files, in a cache folder of the test's own (`XDG_CACHE_HOME`). The
entries that must be used or written again are checked together, as a user's cache
holds them: one process validates a rock of its own size for each case (and an arch),
each case then does to its rock's entry what it tests, and one more process validates
them all; each test asserts on its own rock's entry.
"""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import struct
import subprocess
import sys
import zipfile
from dataclasses import dataclass

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.terrain import mesh_cache, meshes
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
    scene: pathlib.Path | list[pathlib.Path],
    cache: pathlib.Path,
    *,
    python: list[str] | None = None,
) -> subprocess.CompletedProcess[str]:
    """`validate SCENE...` in a process of its own, `cache` its XDG_CACHE_HOME."""
    command = python or [sys.executable, "-P", "-m", "ecs_tentacles"]
    scenes = scene if isinstance(scene, list) else [scene]
    try:
        return subprocess.run(
            [*command, "validate", *map(str, scenes)],
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


# the cases the shared runs check, each with a rock of its own size (an entry of its own):
# what is done to its entry between the two runs
UNTOUCHED = ["a box"]
DAMAGED = ["truncated", "one byte changed", "empty"]
NOT_REGULAR = ["FIFO", "symlink to a FIFO", "symlink to the entry"]
NOT_THE_MESHS = ["a flat piece", "a 1 km tetrahedron", "another mesh's entry"]
SIDES = {
    case: round(ROCK_SIDE + 0.01 * i, 2)
    for i, case in enumerate([*UNTOUCHED, *DAMAGED, *NOT_REGULAR, *NOT_THE_MESHS])
}
OTHER_SIDE = 0.3  # metres: the smaller rock whose entry "another mesh's entry" copies
ARCH = "an arch"


def size_of(entry: pathlib.Path) -> float:
    """Twice the largest |coordinate| of an entry's pieces (laid out as `mesh_cache`'s
    docstring says): a box rock's side."""
    data = entry.read_bytes()
    head = len(mesh_cache.MAGIC) + 32
    (count,) = struct.unpack_from("<I", data, head)
    vertices = np.frombuffer(data[head + 4 + 4 * count : -32], "<f8")
    return round(2 * float(np.abs(vertices).max()), 3)


def spoil(case: str, entry: pathlib.Path, good: bytes, other: bytes, aside: pathlib.Path) -> None:
    """Do to `entry` (holding `good`) what `case` tests; `other` is the smaller rock's
    entry, `aside` a folder outside the cache."""
    if case in UNTOUCHED:
        return
    if case == "truncated":  # failed every run (`error: run: BadZipFile`, naming no file)
        entry.write_bytes(good[: len(good) // 2])
    elif case == "one byte changed":
        middle = len(good) // 2
        entry.write_bytes(good[:middle] + bytes([good[middle] ^ 0x40]) + good[middle + 1 :])
    elif case == "empty":
        entry.write_bytes(b"")
    elif case in NOT_REGULAR:  # a FIFO blocked `validate` forever (and kept its first SIGTERM)
        entry.unlink()
        if case == "FIFO":
            os.mkfifo(entry)
        elif case == "symlink to a FIFO":
            os.mkfifo(aside / "pipe")
            entry.symlink_to(aside / "pipe")
        else:  # even a good one: the cache's entries are files, never links to elsewhere
            (aside / "elsewhere").write_bytes(good)
            entry.symlink_to(aside / "elsewhere")
    elif case == "another mesh's entry":
        entry.write_bytes(other)
    else:  # laid out as this package lays its entries out: their digests check
        assert case in NOT_THE_MESHS, case
        entry.write_bytes(mesh_cache.encode(entry.stem, forged(case, SIDES[case])))
        assert entry.read_bytes() != good


@dataclass
class Together:
    """The second shared run and what the tests compare it with, by case."""

    done: subprocess.CompletedProcess[str]
    cache: pathlib.Path
    scenes: dict[str, pathlib.Path]
    entries: dict[str, pathlib.Path]  # every entry the cache should hold (and "other")
    good: dict[str, bytes]  # each entry as the first run wrote it
    before: dict[str, os.stat_result]  # each entry before the second run


@pytest.fixture(scope="module")
def together(tmp_path_factory: pytest.TempPathFactory) -> Together:
    """One process validates every case's rock, the arch and the smaller rock into one
    cache; each case's entry is spoiled as the case says; one more process validates
    every case's scene and the arch's."""
    folder = tmp_path_factory.mktemp("together")
    cache = folder / "cache"
    scenes = {case: rock_scene(folder / f"rock {side}", side) for case, side in SIDES.items()}
    scenes[ARCH] = rock_scene(folder / "arch")
    arch(scenes[ARCH].parent / "rock.obj")
    other = rock_scene(folder / "other", side=OTHER_SIDE)
    first = validate([*scenes.values(), other], cache)
    assert (first.returncode, first.stderr) == (0, ""), first.stderr
    by_size = {size_of(entry): entry for entry in entries(cache)}
    assert len(by_size) == len(scenes) + 1, sorted(by_size)
    found = {case: by_size.pop(side) for case, side in SIDES.items()}
    found["other"] = by_size.pop(OTHER_SIDE)
    [found[ARCH]] = by_size.values()
    good = {case: entry.read_bytes() for case, entry in found.items()}
    for case in SIDES:
        aside = folder / f"aside {case}"
        aside.mkdir()
        spoil(case, found[case], good[case], good["other"], aside)
    before = {case: entry.lstat() for case, entry in found.items()}
    done = validate(list(scenes.values()), cache)
    return Together(done, cache, scenes, found, good, before)


def assert_validated(together: Together, case: str) -> None:
    """The shared run said ok for `case`'s scene and nothing else; the cache holds every
    rock's entry and nothing more (no temporary file left either)."""
    done = together.done
    assert (done.returncode, done.stderr) == (0, ""), done.stderr
    assert f"{together.scenes[case]}: ok (" in done.stdout, done.stdout
    assert entries(together.cache) == sorted(together.entries.values())


@pytest.mark.parametrize("mesh", [*UNTOUCHED, ARCH])
def test_a_good_entry_is_used_by_the_next_process(together: Together, mesh: str) -> None:
    """The checks pass what the decomposition wrote (an arch's CoACD pieces reach a
    little past its box): the next run reads the entry, no decomposition rewrites it."""
    assert_validated(together, mesh)
    before, after = together.before[mesh], together.entries[mesh].stat()
    assert (after.st_ino, after.st_mtime_ns) == (before.st_ino, before.st_mtime_ns)


def assert_decomposed_again(together: Together, case: str) -> None:
    """`validate` says ok, and the entry is the rock's own again (a regular file)."""
    assert_validated(together, case)
    entry = together.entries[case]
    assert entry.is_file() and not entry.is_symlink()
    assert entry.read_bytes() == together.good[case]


@pytest.mark.parametrize("damage", DAMAGED)
def test_a_damaged_entry_is_ignored_and_written_again(together: Together, damage: str) -> None:
    """A truncated entry failed every run (`error: run: BadZipFile`, naming no file)
    until deleted by hand."""
    assert_decomposed_again(together, damage)


@pytest.mark.parametrize("kind", NOT_REGULAR)
def test_an_entry_that_is_not_a_regular_file_is_never_read(together: Together, kind: str) -> None:
    """A FIFO in the cache blocked `validate` forever (and kept its first SIGTERM)."""
    assert_decomposed_again(together, kind)


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


@pytest.mark.parametrize("kind", NOT_THE_MESHS)
def test_an_entry_that_is_not_the_meshs_pieces_is_replaced(together: Together, kind: str) -> None:
    """Entries that pass every check of their own format: a degenerate piece made the
    good rock refused on every run; a 1 km tetrahedron replaced the 0.5 m rock (the
    creature then inside it); a smaller rock's entry under this rock's name replaced it
    silently. Each is ignored: the rock decomposed again, its entry written afresh."""
    assert_decomposed_again(together, kind)


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


def test_validate_starts_one_mesh_worker_for_all_its_scenes(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each scene's build started a worker of its own (its imports: about 1 CPU-second
    each), also where every entry was cached; now `validate` hands the idle worker from
    one scene to the next and ends it with the command."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setattr(meshes, "_KNOWN", {})  # this process has read no mesh yet
    scenes = [str(rock_scene(tmp_path / f"rock {i}", 0.437 + 0.01 * i)) for i in range(3)]
    started: list[meshes._Worker] = []
    start = meshes._Worker.__init__

    def counted(worker: meshes._Worker) -> None:
        started.append(worker)
        start(worker)

    monkeypatch.setattr(meshes._Worker, "__init__", counted)
    for run in ("decomposed", "cached"):
        assert main(["validate", *scenes]) == 0, run
        assert len(started) == 1, run
        assert started[0].process.poll() is not None, run  # ended with the command
        assert len(entries(tmp_path / "cache")) == 3
        started.clear()
        monkeypatch.setattr(meshes, "_KNOWN", {})  # as the next process: read from the cache
