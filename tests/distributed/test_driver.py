"""Bakes on a local Ray (2 CPUs, started once): equal to local bakes, wedges, retries,
--resume and Ctrl-C. Skipped without the `ray` extra."""

from __future__ import annotations

import hashlib
import json
import logging
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.distributed.merge import merge_takes
from ecs_tentacles.distributed.shards import default_tasks, plan_shards
from ecs_tentacles.distributed.task import CRASH_DIR, bake_shard
from ecs_tentacles.distributed.work import shard_key, work_folder
from ecs_tentacles.export.bake import BakePlan
from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.take import Take
from ecs_tentacles.terrain.presets import rocky
from tests.conftest import STOPS

ray = pytest.importorskip("ray", reason="the `ray` extra is not installed")

SECONDS = "0.3"


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A local Ray with 2 CPUs; yields the folder its workers read crash requests from."""
    crashes = tmp_path_factory.mktemp("crashes")
    os.environ[CRASH_DIR] = str(crashes)  # inherited by the workers Ray starts
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR)
    yield crashes
    ray.shutdown()
    del os.environ[CRASH_DIR]


@pytest.fixture
def crowd(tmp_path: Path) -> Path:
    """Six creatures that the planner splits into 2 shards for a 0.3 s bake."""
    path = tmp_path / "crowd.json"
    path.write_text(json.dumps(crowd_scene(6, seed=3)))
    return path


def bake(scene: Path, out: Path, *extra: str) -> int:
    argv = ["bake", str(scene), "--seconds", SECONDS, "--fps", "30", "--out", str(out)]
    return main([*argv, "--quiet", *extra])


def shards_of(scene: Path) -> tuple[BakePlan, list[list[int]]]:
    plan = BakePlan.make(scene, seconds=float(SECONDS), fps=30)
    return plan, plan_shards(plan.scene, plan.seconds, default_tasks(2)).shards


def test_sharded_bake_equals_local_bake_byte_for_byte(
    cluster: Path, crowd: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, shards = shards_of(crowd)
    assert len(shards) >= 2
    assert bake(crowd, tmp_path / "local.npz") == 0
    assert bake(crowd, tmp_path / "ray.npz", "--ray") == 0
    assert (tmp_path / "ray.npz").read_bytes() == (tmp_path / "local.npz").read_bytes()
    err = capsys.readouterr().err
    assert f"ray: {len(shards)} shards from" in err
    assert f"ray: {len(shards)} shard(s) baked, 0 resumed, 0 re-baked" in err
    assert not work_folder(tmp_path / "ray.npz").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.json", "local.npz", "ray.npz"]


def test_a_bake_that_shows_no_bar_starts_no_actor(
    cluster: Path, crowd: Path, tmp_path: Path
) -> None:
    """The shards count their frames to an actor for the progress bar: a Ray worker
    process of its own (its start and imports: about a CPU-second). A bake that shows no
    bar (--quiet, or not on a terminal) started one all the same."""
    from ray._private import state  # the actors table, the ended ones too (no dashboard)

    before = len(state.actors())
    assert bake(crowd, tmp_path / "ray.npz", "--ray") == 0
    assert len(state.actors()) == before


def test_a_sharded_bake_on_terrain_equals_the_local_bake(
    cluster: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every shard builds the same heightfield and rocks; the merged take holds them once."""
    scene = crowd_scene(6, seed=3)
    positions = np.array([c["position"] for c in scene["creatures"]], dtype=np.float64)
    scene["terrain"] = rocky(positions, max(creature_reach(c) for c in scene["creatures"]), 3)
    path = tmp_path / "rocky.json"
    path.write_text(json.dumps(scene))
    assert len(shards_of(path)[1]) >= 2
    assert bake(path, tmp_path / "local.npz") == 0
    assert bake(path, tmp_path / "ray.npz", "--ray") == 0
    assert (tmp_path / "ray.npz").read_bytes() == (tmp_path / "local.npz").read_bytes()
    assert [name for name, _ in Take.load(tmp_path / "ray.npz").ground_meshes()] == [
        "terrain",
        "obstacles",
    ]


def test_creatures_of_declared_shards_that_meet_are_baked_again_together(
    cluster: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tentacles = {"count": 4, "links": 5}
    scene: dict[str, Any] = {
        "version": 1,
        "name": "meet",
        "creatures": [
            {
                "name": "a",
                "position": [0, 0],
                "tentacles": tentacles,
                "goals": [{"position": [2, 0]}],
            },
            {
                "name": "b",
                "position": [0.35, 0, 0.45],  # falls onto a
                "tentacles": tentacles,
                "goals": [{"position": [-1, 0]}],
            },
            {"name": "c", "position": [6, 6], "tentacles": tentacles},
        ],
        "shards": [["a", "c"], ["b"]],
    }
    path = tmp_path / "meet.json"
    path.write_text(json.dumps(scene))
    assert bake(path, tmp_path / "local.npz") == 0
    assert bake(path, tmp_path / "ray.npz", "--ray") == 0
    assert (tmp_path / "ray.npz").read_bytes() == (tmp_path / "local.npz").read_bytes()
    err = capsys.readouterr().err
    assert "ray: a and b came within contact range at" in err
    assert "3 shard(s) baked, 0 resumed, 1 re-baked together" in err
    # the check matters: baked apart, a and b would not have pushed each other
    plan = BakePlan.make(path, seconds=float(SECONDS), fps=30)
    apart = merge_takes([(m, bake_shard(plan, m).take) for m in ([0, 2], [1])])
    assert not np.array_equal(apart.pos, Take.load(tmp_path / "local.npz").pos)


def test_a_2x2_wedge_writes_4_outputs_and_their_index(
    cluster: Path, crowd: Path, tmp_path: Path
) -> None:
    out = tmp_path / "wedge"
    out.mkdir()
    wedges = ["--wedge", "seed=1..2", "--wedge", "creatures[0].tentacles.strength=20,30.5"]
    assert bake(crowd, out / "{name}.npz", *wedges, "--ray") == 0
    index = json.loads((out / "wedge.json").read_text())
    names = [f"seed-{s}_creatures0.tentacles.strength-{v}" for s in (1, 2) for v in ("20", "30.5")]
    assert [row["name"] for row in index["outputs"]] == names
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [*(f"{n}.npz" for n in names), "wedge.json"]
    )
    for row in index["outputs"]:
        data = (out / row["file"]).read_bytes()
        assert row["sha256"] == hashlib.sha256(data).hexdigest()
    assert index["outputs"][3]["parameters"] == {"seed": 2, "creatures[0].tentacles.strength": 30.5}
    # each output is the bake of its variant
    variant = json.loads(crowd.read_text())
    variant["seed"] = 2
    variant["creatures"][0]["tentacles"]["strength"] = 30.5
    (tmp_path / "variant.json").write_text(json.dumps(variant))
    assert bake(tmp_path / "variant.json", tmp_path / "variant.npz") == 0
    assert (tmp_path / "variant.npz").read_bytes() == (out / f"{names[3]}.npz").read_bytes()


def test_a_killed_workers_shard_is_retried_and_the_take_is_unchanged(
    cluster: Path, crowd: Path, tmp_path: Path
) -> None:
    plan, shards = shards_of(crowd)
    (cluster / shard_key(plan, shards[0], False)).write_text("crash once")
    assert bake(crowd, tmp_path / "local.npz") == 0
    assert bake(crowd, tmp_path / "ray.npz", "--ray") == 0
    assert list(cluster.glob("*.claimed.*")), "the worker never crashed"
    assert (tmp_path / "ray.npz").read_bytes() == (tmp_path / "local.npz").read_bytes()


def test_a_failed_shard_is_named_and_resume_bakes_only_the_others(
    cluster: Path, crowd: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan, shards = shards_of(crowd)
    (cluster / shard_key(plan, shards[-1], False)).write_text("crash")
    out = tmp_path / "ray.npz"
    assert bake(crowd, out, "--ray", "--retries", "0") == 1
    err = capsys.readouterr().err
    names = ", ".join(plan.scene["creatures"][i]["name"] for i in shards[-1][:3])
    assert f"error: shard {len(shards) - 1} ({names}" in err
    assert "failed: WorkerCrashedError: The worker died unexpectedly" in err
    assert not out.exists()
    kept = list(work_folder(out).glob("*.npz"))
    assert len(kept) == len(shards) - 1
    assert bake(crowd, out, "--ray", "--resume") == 0
    err = capsys.readouterr().err
    assert f"ray: 1 shard(s) baked, {len(shards) - 1} resumed" in err
    assert bake(crowd, tmp_path / "local.npz") == 0
    assert out.read_bytes() == (tmp_path / "local.npz").read_bytes()
    assert not work_folder(out).exists()


def _moved(path: Path) -> None:
    """Rewrite the kept shard `path` as someone without the bake's key could: well-formed,
    every body 5 m away."""
    from ecs_tentacles.take import write_npz

    with np.load(path) as npz:
        arrays = {name: npz[name] for name in npz.files}
    write_npz(path, {**arrays, "pos": arrays["pos"] + np.float32(5.0)})


def test_a_changed_kept_shard_is_named_and_baked_again_on_resume(
    cluster: Path, crowd: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before, the moved creatures were merged (exit 0). A shard with a 400-digit or
    deeply nested header (which failed every --resume with exit 1) meets the same
    signature check first; signed ones that do not read are refused in test_work.py."""
    plan, shards = shards_of(crowd)
    (cluster / shard_key(plan, shards[-1], False)).write_text("crash")
    out = tmp_path / "ray.npz"
    assert bake(crowd, out, "--ray", "--retries", "0") == 1
    _moved(work_folder(out) / f"{shard_key(plan, shards[0], False)}.npz")
    capsys.readouterr()
    assert bake(crowd, out, "--ray", "--resume") == 0
    err = capsys.readouterr().err.splitlines()
    names = ", ".join(plan.scene["creatures"][i]["name"] for i in shards[0][:3])
    said = [line for line in err if "kept result not used" in line]
    assert len(said) == 1 and said[0].startswith(f"ray: shard 0 ({names}"), err
    assert said[0].endswith(
        "): kept result not used: it changed after this user's bake wrote it"
        " (the signature differs); baking it again"
    )
    assert f"ray: 2 shard(s) baked, {len(shards) - 2} resumed, 0 re-baked" in "\n".join(err)
    assert bake(crowd, tmp_path / "local.npz") == 0
    assert out.read_bytes() == (tmp_path / "local.npz").read_bytes()
    assert not work_folder(out).exists()


@pytest.mark.parametrize(("stop", "code", "message"), STOPS)
@pytest.mark.usefixtures("ctrl_c_reaches_children")
def test_ctrl_c_or_sigterm_cancels_the_bake_and_leaves_no_output(
    cluster: Path, crowd: Path, tmp_path: Path, stop: int, code: int, message: str
) -> None:
    address = ray.get_runtime_context().gcs_address
    process = _running_bake(crowd, tmp_path, "--ray", address)
    process.send_signal(stop)
    _, err = process.communicate(timeout=60)
    assert process.returncode == code, err
    assert err.splitlines() == [message]  # one line: no Ray dump (its handler is not ours)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.json"]
    deadline = time.monotonic() + 60.0  # the cancelled tasks free their CPUs
    while ray.available_resources().get("CPU") != 2 and time.monotonic() < deadline:
        time.sleep(0.2)
    assert ray.available_resources().get("CPU") == 2


def _running_bake(scene: Path, folder: Path, *ray: str) -> subprocess.Popen[str]:
    """A 20 s `bake SCENE --out FOLDER/ray.npz` on Ray (options `ray`) in a process of its
    own, returned once its tasks run (a second after it reports the shards)."""
    argv = [sys.executable, "-m", "ecs_tentacles", "bake", str(scene), "--seconds", "20"]
    process = subprocess.Popen(
        [*argv, "--out", str(folder / "ray.npz"), *ray, "--quiet"],
        stderr=subprocess.PIPE,
        text=True,
        cwd=folder,
    )
    assert process.stderr is not None
    line = process.stderr.readline()
    while line and not line.startswith("ray:"):
        line = process.stderr.readline()
    time.sleep(1.0)  # the tasks are running
    return process


def _ray_processes_of(bake: int) -> set[tuple[int, float]]:
    """(pid, start time) of every living process of the Ray that process `bake` started:
    its descendants and whatever names its Ray session (`session_<date>_<bake pid>`,
    Ray's own naming) on its command line or in its open files (an agent or worker may
    have been re-parented). Zombies are dead: they hold no memory, and whether they are
    reaped is up to whoever adopted them."""
    import psutil

    found = set()
    session = re.compile(rf"session_[0-9_-]+_{bake}(?![0-9])")
    try:
        family = psutil.Process(bake).children(recursive=True)
    except psutil.Error:
        family = []
    for process in family:
        try:
            if process.status() != psutil.STATUS_ZOMBIE:
                found.add((process.pid, process.create_time()))
        except psutil.Error:
            continue
    for process in psutil.process_iter(["cmdline", "create_time", "status"]):
        if process.info["status"] == psutil.STATUS_ZOMBIE:
            continue
        try:  # agents and workers retitle themselves `ray::...`: their open logs name it
            names = [*(process.info["cmdline"] or ()), *(f.path for f in process.open_files())]
        except psutil.Error:
            continue
        if session.search(" ".join(names)):
            found.add((process.pid, process.info["create_time"]))
    return found


def _still_there(processes: set[tuple[int, float]], seconds: float) -> set[tuple[int, float]]:
    """Which of `processes` still live (not zombies) after waiting up to `seconds` for
    them to go (polling: a loaded machine takes its time)."""
    import psutil

    def alive(pid: int, created: float) -> bool:
        try:
            process = psutil.Process(pid)
            return (
                abs(process.create_time() - created) < 0.01
                and process.status() != psutil.STATUS_ZOMBIE
            )
        except psutil.Error:
            return False

    deadline = time.monotonic() + seconds
    left = {p for p in processes if alive(*p)}
    while left and time.monotonic() < deadline:
        time.sleep(0.2)
        left = {p for p in left if alive(*p)}
    return left


def test_a_killed_bake_leaves_no_ray_processes_behind(crowd: Path, tmp_path: Path) -> None:
    """SIGKILL cannot be handled: the watchdog `bake --ray` starts with its local Ray
    ends that Ray's processes (GCS, raylet, agents, workers) instead."""
    process = _running_bake(crowd, tmp_path, "--ray", "--cpus", "1")
    started = _ray_processes_of(process.pid)
    assert started  # a local Ray of its own
    process.kill()
    process.wait(timeout=60)
    started |= _ray_processes_of(process.pid)  # any started while it was being killed
    left = _still_there(started, 60.0)  # the watchdog looks every second, then 2 s of grace
    names = sorted(_describe(pid) for pid, _ in left)
    assert not left, (
        f"{len(left)} of {len(started)} Ray processes outlived the killed bake: {names}"
    )


HELD = """
import os, sys, time

import ray._private.services
import ray._private.worker

from ecs_tentacles.cli import main

where, when = sys.argv[1], sys.argv[2]
module = ray._private.services if where == "start_raylet" else ray._private.worker
real = getattr(module, where)


def held(*args, **kwargs):
    if when == "after":
        real(*args, **kwargs)
    open(os.environ["HELD_MARKER"], "w").close()  # the test sends SIGTERM now
    while True:
        time.sleep(0.05)


setattr(module, where, held)
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.parametrize(
    ("where", "when"),
    [
        ("start_raylet", "after"),  # GCS and raylet up, the raylet starting its agents
        ("connect", "before"),  # every process up, the driver not connected yet
    ],
)
def test_sigterm_while_ray_starts_is_one_line_exit_143_and_leaves_no_ray_behind(
    crowd: Path, tmp_path: Path, where: str, when: str
) -> None:
    """`ray.init` takes seconds and puts its own SIGTERM handler in first (exit 15, no
    line). The bake is held inside `ray.init` (Ray's function `where` wrapped in a
    script of the test's: no timing), then stopped: the same contract as after the
    start, and nothing of its Ray left."""
    assert callable(getattr(ray._private.services, "start_raylet", None))
    assert callable(getattr(ray._private.worker, "connect", None))
    script, marker = tmp_path / "held.py", tmp_path / "held"
    script.write_text(HELD)
    argv = [sys.executable, str(script), where, when, "bake", str(crowd), "--seconds", "20"]
    process = subprocess.Popen(
        [*argv, "--out", str(tmp_path / "ray.npz"), "--ray", "--cpus", "1", "--quiet"],
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "HELD_MARKER": str(marker)},
    )
    deadline = time.monotonic() + 300.0
    while not marker.exists():
        assert process.poll() is None, process.communicate()[1]
        assert time.monotonic() < deadline, "Ray's start never reached the held point"
        time.sleep(0.05)
    started = _ray_processes_of(process.pid)
    assert started  # Ray's start had started processes
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 143, err
    lines = [line for line in err.splitlines() if not line.startswith("bake: ")]  # its plan
    assert lines == ["error: stopped by SIGTERM; partial outputs removed"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.json", "held", "held.py"]
    started |= _ray_processes_of(process.pid)
    left = _still_there(started, 10.0)  # ended before the bake exited: no watchdog's wait
    names = sorted(_describe(pid) for pid, _ in left)
    assert not left, f"{len(left)} of {len(started)} Ray processes outlived the bake: {names}"


def _describe(pid: int) -> str:
    import psutil

    try:
        return " ".join(psutil.Process(pid).cmdline())[:120]
    except psutil.Error:
        return f"{pid} (gone)"
