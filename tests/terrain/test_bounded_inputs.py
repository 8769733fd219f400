"""Terrain inputs cost a bounded time and memory, and bad ones are refused in one line
naming the field, by `validate` as by `run`: meshes (coordinates, volume, decomposition
budget, one decomposition per distinct file), height images (real PNGs, side caps,
decompression bombs, heights clamped) and big `heights` arrays."""

from __future__ import annotations

import json
import pathlib
import sys
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main


def scene(terrain: dict[str, Any]) -> dict[str, Any]:
    return {"version": 1, "terrain": terrain, "creatures": [{"name": "c0", "position": [0, 0]}]}


def write_scene(folder: pathlib.Path, terrain: dict[str, Any]) -> pathlib.Path:
    path = folder / "scene.json"
    path.write_text(json.dumps(scene(terrain)))
    return path


class TooManyCalls(Exception):
    pass


def test_a_million_heights_validate_without_a_python_call_per_number(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """1024 x 1024 `heights` (the schema's largest) are checked with numpy, not number by
    number (31 s before); a bad one among them is still named by its path."""
    heights: list[list[Any]] = (np.arange(1024 * 1024).reshape(1024, 1024) % 7).tolist()
    path = write_scene(tmp_path, {"heightfield": {"size": [10, 10], "heights": heights}})
    assert main(["validate", str(path)]) == 0  # imports and caches warmed
    capsys.readouterr()
    calls = 0

    def count(frame: object, event: str, arg: object) -> None:
        nonlocal calls
        if event == "call":
            calls += 1
            if calls > 1_000_000:  # one per number: stop there
                raise TooManyCalls

    sys.setprofile(count)
    try:
        code = main(["validate", str(path)])
    finally:
        sys.setprofile(None)
    assert code == 0 and calls < 1_000_000
    assert "ok" in capsys.readouterr().out
    heights[700][300] = 1000.5
    path.write_text(json.dumps(scene({"heightfield": {"size": [10, 10], "heights": heights}})))
    assert main(["validate", str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [
        f"error: {path}: terrain.heightfield.heights[700][300]: must be in [-1000, 1000],"
        " got 1000.5"
    ]


def check(folder: pathlib.Path, terrain: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> str:
    """`validate` and `run` of the scene both exit 2 with one line naming the field;
    returns that line (validate's, led by the scene's path)."""
    path = write_scene(folder, terrain)
    lines = {}
    for command in (["validate", str(path)], ["run", str(path), "--frames", "1", "--quiet"]):
        code = main(command)
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1, (command[0], code, err)
        lines[command[0]] = err[0]
    assert lines["validate"] == lines["run"].replace("error: ", f"error: {path}: ", 1)
    return lines["validate"]


TETRAHEDRON = "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"


def mesh_terrain(file: str, scale: float = 1.0) -> dict[str, Any]:
    return {"obstacles": [{"shape": "mesh", "file": file, "position": [4, 0, 0], "scale": scale}]}


@pytest.mark.parametrize(
    ("far", "scale"), [(1e300, 1.0), (1e100, 1.0), (2.0, 1000.0)], ids=["1e300", "1e100", "scaled"]
)
def test_mesh_coordinates_are_bounded_before_any_geometry_code_sees_them(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str], far: float, scale: float
) -> None:
    """A 76-byte OBJ with vertices at 1e300 crashed every command in qhull (exit 139)."""
    (tmp_path / "far.obj").write_text(
        f"v 0 0 0\nv {far:g} 0 0\nv 0 {far:g} 0\nv 0 0 {far:g}\n{TETRAHEDRON}"
    )
    line = check(tmp_path, mesh_terrain("far.obj", scale), capsys)
    assert "terrain.obstacles[0].file: far.obj: a vertex lies" in line
    assert "at most 1000 m" in line


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("v 0 0 0\nv 1 1 1\nv 2 2 2\nv 3 3 3\nf 1 2 3\nf 2 3 4\n", "lie on a line"),
        ("v 0 0 0\nv 1 0 0.5\nv 0 1 0.3\nf 1 2 3\n", "no volume"),
        (  # a tilted square, two triangles: every axis has a range, the mesh no volume
            "v 0 0 0\nv 1 0 1\nv 1 1 2\nv 0 1 1\nf 1 2 3\nf 1 3 4\n",
            "lie on a plane",
        ),
    ],
    ids=["collinear", "one triangle", "tilted square"],
)
def test_a_mesh_without_volume_is_refused(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str], text: str, says: str
) -> None:
    (tmp_path / "flat.obj").write_text(text)
    line = check(tmp_path, mesh_terrain("flat.obj"), capsys)
    assert "terrain.obstacles[0].file: flat.obj: the mesh has no volume" in line
    assert says in line


def arch(path: pathlib.Path) -> None:
    """A concave mesh (two legs and a lintel) that CoACD splits."""
    import trimesh

    boxes = [
        trimesh.creation.box(
            (0.3, 1.0, 1.0), trimesh.transformations.translation_matrix((x, 0, 0.5))
        )
        for x in (-0.6, 0.6)
    ]
    top = trimesh.transformations.translation_matrix((0, 0, 1.15))
    trimesh.util.concatenate([*boxes, trimesh.creation.box((1.5, 1.0, 0.3), top)]).export(path)


def test_a_mesh_named_by_many_obstacles_is_decomposed_once_and_cached(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """1,000 references to one concave OBJ ran past 15 minutes (1.4 s of CoACD each)."""
    from ecs_tentacles.terrain import meshes
    from ecs_tentacles.terrain.mesh_cache import cache_folder

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setattr(meshes, "_KNOWN", {})  # as a new process (an arch of test_plugin's)
    arch(tmp_path / "arch.obj")
    rocks = [
        {"shape": "mesh", "file": "arch.obj", "position": [20 + 3 * (i % 20), 3 * (i // 20), 0]}
        for i in range(200)
    ]
    path = write_scene(tmp_path, {"obstacles": rocks})
    assert main(["validate", str(path)]) == 0, capsys.readouterr().err
    kept = sorted(cache_folder().iterdir())
    assert len(kept) == 1 and kept[0].suffix == ".pieces"  # one entry, no temporary left
    stamp = kept[0].stat().st_mtime_ns
    assert main(["run", str(path), "--frames", "1", "--quiet"]) == 0, capsys.readouterr().err
    assert sorted(cache_folder().iterdir()) == kept and kept[0].stat().st_mtime_ns == stamp


def soup(path: pathlib.Path) -> None:
    """A 10 KB soup of 100 random triangles: CoACD took 119-287 s and 711 MB over it."""
    rng = np.random.default_rng(0)
    corners = rng.uniform(-1.0, 1.0, (300, 3))
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in corners]
    lines += [f"f {3 * k + 1} {3 * k + 2} {3 * k + 3}" for k in range(100)]
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("budget", ["time", "memory"])
def test_a_mesh_over_its_budget_is_one_line(
    tmp_path: pathlib.Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    budget: str,
) -> None:
    from ecs_tentacles.terrain import meshes

    if budget == "time":
        monkeypatch.setattr(meshes, "MESH_SECONDS", 2.0)
    else:  # the soup needs about 700 MB: certain to pass 300 MB, however slow the machine
        monkeypatch.setattr(meshes, "MESH_MEMORY_MB", 300)
        monkeypatch.setattr(meshes, "MESH_SECONDS", 1800.0)
        monkeypatch.setattr(meshes, "SCENE_MESH_SECONDS", 1800.0)
    soup(tmp_path / "soup.obj")
    path = write_scene(tmp_path, mesh_terrain("soup.obj"))
    assert main(["validate", str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "terrain.obstacles[0].file: soup.obj: " in lines[0], lines
    assert ("over 2 s" if budget == "time" else "over 300 MB") in lines[0]
    assert "the budget per mesh" in lines[0]


def _children(pid: int) -> list[int]:
    found = []
    for entry in pathlib.Path("/proc").iterdir():
        try:
            fields = (entry / "stat").read_text().rpartition(")")[2].split()
        except (OSError, ValueError):
            continue
        if entry.name.isdigit() and int(fields[1]) == pid:
            found.append(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = pathlib.Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not pathlib.Path("/proc").is_dir(), reason="reads /proc")
def test_sigterm_ends_a_mesh_decomposition_promptly(tmp_path: pathlib.Path) -> None:
    """SIGTERM was ignored for 107 s while CoACD ran; now the worker is killed with the
    command, which exits 143 with one line."""
    import signal
    import subprocess
    import time

    soup(tmp_path / "soup.obj")
    path = write_scene(tmp_path, mesh_terrain("soup.obj"))
    command = [sys.executable, "-m", "ecs_tentacles", "validate", str(path)]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        workers: list[int] = []
        while not workers and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.2)
            workers = _children(process.pid)
        assert workers, "no worker started"
        time.sleep(2.0)  # well into the decomposition (the worker's imports take ~1 s)
        process.send_signal(signal.SIGTERM)
        sent = time.monotonic()
        _, err = process.communicate(timeout=30)
        assert time.monotonic() - sent < 10
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 143
    assert err.strip().splitlines() == ["error: stopped by SIGTERM; partial outputs removed"]
    deadline = time.monotonic() + 20  # a loaded machine may take a moment to reap it
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(pid) for pid in workers)


def png(path: pathlib.Path, pixels: np.ndarray) -> None:
    from PIL import Image

    Image.fromarray(pixels).save(path, format="PNG")


def bomb(path: pathlib.Path, side: int) -> None:
    """A real `side` x `side` single-colour 8-bit PNG, written row by row (a few hundred
    kB that decode to side^2 bytes)."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    squeeze = zlib.compressobj(1)
    row = bytes(side + 1)  # filter byte 0, then black pixels
    stream = b"".join(squeeze.compress(row) for _ in range(side)) + squeeze.flush()
    header = struct.pack(">IIBBBBB", side, side, 8, 0, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", stream) + chunk(b"IEND", b"")
    )


def image_terrain(file: str, height: float = 1.0) -> dict[str, Any]:
    return {"heightfield": {"size": [8, 8], "image": file, "height": height}}


def test_height_images_are_capped_like_resolution(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 16 KB 4096 x 4096 PNG cost 1.1-2.5 GB; sides are now at most 1024."""
    png(tmp_path / "big.png", np.full((1025, 64), 128, np.uint8))
    line = check(tmp_path, image_terrain("big.png"), capsys)
    assert "terrain.heightfield.image: big.png: 64 x 1025 pixels; sides must be 3 to 1024" in line


def test_a_decompression_bomb_exits_2_naming_the_field(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bomb(tmp_path / "bomb.png", 20_000)
    line = check(tmp_path, image_terrain("bomb.png"), capsys)
    assert "terrain.heightfield.image: bomb.png: 20000 x 20000 pixels; sides must be 3" in line
    assert "Error" not in line  # no Pillow class name


def test_only_real_pngs_are_read(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 32-bit TIFF named .png gave heights of 3,277 km."""
    from PIL import Image

    Image.fromarray(np.full((64, 64), 70_000, np.int32)).save(tmp_path / "tiff.png", format="TIFF")
    line = check(tmp_path, image_terrain("tiff.png"), capsys)
    assert "terrain.heightfield.image: tiff.png: not a PNG image" in line


def test_heights_from_an_image_stay_within_0_and_height(tmp_path: pathlib.Path) -> None:
    from ecs_tentacles.terrain.heights import heightfield

    pixels = np.zeros((8, 8), np.uint16)
    pixels[2, 3] = 65535
    png(tmp_path / "hill.png", pixels)
    field = heightfield(image_terrain("hill.png", 0.4)["heightfield"], tmp_path)
    assert field.heights.min() == 0.0 and field.heights.max() == pytest.approx(0.4)


@pytest.mark.parametrize(
    ("make", "says"),
    [
        (None, "no such file in the scene's folder"),
        ("one pixel", "1 x 1 pixels; sides must be 3 to 1024"),
        ("text", "not a PNG image"),
        ("nul", "a file name cannot hold a NUL character"),
    ],
    ids=["missing", "one pixel", "text", "nul"],
)
def test_validate_reads_the_terrain_files_as_run_does(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str], make: str | None, says: str
) -> None:
    """`validate` said ok where `run` refused (the files were not read)."""
    name = "a\x00b.png" if make == "nul" else "ground.png"
    if make == "one pixel":
        png(tmp_path / name, np.zeros((1, 1), np.uint8))
    elif make == "text":
        (tmp_path / name).write_text("not an image\n")
    line = check(tmp_path, image_terrain(name), capsys)
    assert "terrain.heightfield.image: " in line and says in line


def test_validate_checks_creatures_against_the_obstacles(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """What the terrain checks at build (a creature inside a rock) `validate` checks too."""
    rock = {"obstacles": [{"shape": "sphere", "position": [0.5, 0, 0], "radius": 0.3}]}
    line = check(tmp_path, rock, capsys)
    assert "creatures[0].position: c0 is inside terrain.obstacles[0]" in line
