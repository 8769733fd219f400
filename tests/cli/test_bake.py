"""`bake`, `export` and `create` on the command line: outputs, one-line errors, kills."""

from __future__ import annotations

import hashlib
import json
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.bake import BakePlan
from ecs_tentacles.export.take_size import take_size
from ecs_tentacles.take import Take
from tests.cli.conftest import refused
from tests.conftest import STOPS
from tests.export.conftest import SMALL_SCENE


def test_bake_writes_a_take_and_reports_it(
    scene: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "take.npz"
    argv = ["bake", str(scene), "--seconds", "0.2", "--fps", "30", "--out", str(out), "--quiet"]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert captured.err == (
        f"bake: {scene} -> {out}: 7 frames at 30 fps (simulated at 60 fps), seed 4\n"
    )
    take = Take.load(out)
    assert captured.out.startswith(
        f"{out}: 7 frames at 30 fps, 1 creature, 13 bodies, 3 suckers, 1 goal; sha256 "
    )
    assert (take.frames, take.fps, take.header["scene"]) == (7, 30.0, "small")
    assert main([*argv, "--seed", "9"]) == 0  # overwrites atomically
    assert Take.load(out).header["seed"] == 9


def test_baking_to_usd_or_glb_equals_exporting_the_take(scene: Path, tmp_path: Path) -> None:
    common = ["--seconds", "0.1", "--quiet"]
    for name in ("take.npz", "direct.usda", "direct.glb"):
        assert main(["bake", str(scene), *common, "--out", str(tmp_path / name)]) == 0
    for name in ("exported.usda", "exported.glb"):
        out = str(tmp_path / name)
        assert main(["export", str(tmp_path / "take.npz"), "--out", out, "--quiet"]) == 0
    for suffix in ("usda", "glb"):
        direct = (tmp_path / f"direct.{suffix}").read_bytes()
        assert direct == (tmp_path / f"exported.{suffix}").read_bytes()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--seconds", "0"], "argument --seconds: must be a finite number > 0, got 0"),
        (["--seconds", "nan"], "argument --seconds: must be a finite number > 0, got nan"),
        (["--seconds", "two"], "argument --seconds: must be a number, got 'two'"),
        (["--seconds", "1", "--fps", "0"], "argument --fps: must be a finite number > 0, got 0"),
        (["--seconds", "1", "--fps", "5000"], "argument --fps: must be <= 1000, got 5000"),
        (["--seconds", "1", "--seed", "-2"], "argument --seed: must be >= 0, got -2"),
        (
            ["--seconds", "1", "--out", "take.mp4"],
            "argument --out: must end in one of .npz, .usd, .usda, .usdc, .glb, got 'take.mp4'",
        ),
        (
            ["--seconds", "1", "--ray", "--retries", "-1"],
            "argument --retries: must be >= 0, got -1",
        ),
        (["--seconds", "1", "--ray", "--cpus", "0"], "argument --cpus: must be >= 1, got 0"),
        (
            ["--seconds", "1", "--out", "no/such/folder/t.npz"],
            "argument --out: folder 'no/such/folder' does not exist",
        ),
    ],
)
def test_bad_bake_arguments_exit_2_with_one_line(
    args: list[str], message: str, scene: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["bake", str(scene), "--out", "t.npz", *args]
    assert refused(argv, capsys) == f"error: {message} (see ecs-tentacles bake --help)\n"


def test_bake_errors_found_after_parsing_exit_2(
    scene: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = str(tmp_path / "t.npz")
    assert main(["bake", str(scene), "--seconds", "0.001", "--out", out]) == 2
    assert capsys.readouterr().err == (
        "error: argument --seconds: 0.001 s is less than one frame at 60 fps\n"
    )
    assert main(["bake", str(tmp_path / "none.json"), "--seconds", "1", "--out", out]) == 2
    assert capsys.readouterr().err == (
        f"error: {tmp_path / 'none.json'}: cannot read scene: No such file or directory\n"
    )
    assert not (tmp_path / "t.npz").exists()


def test_export_errors_exit_2_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"\x00" * 10)
    assert main(["export", str(junk), "--out", str(tmp_path / "a.glb")]) == 2
    assert capsys.readouterr().err == f"error: {junk}: not a take file (not an npz archive)\n"
    with pytest.raises(SystemExit):
        main(["export", str(junk), "--out", str(tmp_path / "a.npz")])
    assert capsys.readouterr().err == (
        "error: argument --out: must end in one of .usd, .usda, .usdc, .glb, got '"
        + str(tmp_path / "a.npz")
        + "' (see ecs-tentacles export --help)\n"
    )
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "pxr" else real(name, *a)
    )
    assert main(["export", str(junk), "--out", str(tmp_path / "a.usd")]) == 2
    assert capsys.readouterr().err == (
        "error: argument --out: writing USD needs usd-core: pip install 'ecs-tentacles[usd]'\n"
    )


def _start_long_bake(out: Path) -> subprocess.Popen[str]:
    """A bake of ten simulated minutes; returns once it has started simulating."""
    process = subprocess.Popen(
        [sys.executable, "-m", "ecs_tentacles.cli", "bake", "octopus", "--seconds", "600"]
        + ["--out", str(out)],
        stderr=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert process.stderr is not None
    assert process.stderr.readline().startswith("bake: ")  # the world is built, stepping now
    return process


def test_a_killed_bake_leaves_no_file_or_the_previous_one(tmp_path: Path) -> None:
    fresh, previous = tmp_path / "fresh" / "take.npz", tmp_path / "old" / "take.npz"
    fresh.parent.mkdir()
    previous.parent.mkdir()
    previous.write_bytes(b"yesterday's take")
    bakes = [_start_long_bake(fresh), _start_long_bake(previous)]
    time.sleep(0.5)  # well inside the simulation
    for process in bakes:
        process.send_signal(signal.SIGKILL)
        assert process.wait(timeout=30) == -signal.SIGKILL
    assert list(fresh.parent.iterdir()) == []
    assert previous.read_bytes() == b"yesterday's take"
    assert list(previous.parent.iterdir()) == [previous]


@pytest.mark.parametrize(("stop", "code", "line"), STOPS)
@pytest.mark.usefixtures("ctrl_c_reaches_children")
def test_an_interrupted_bake_exits_with_one_line_and_leaves_nothing(
    tmp_path: Path, stop: signal.Signals, code: int, line: str
) -> None:
    out = tmp_path / "take.usda"
    process = _start_long_bake(out)
    time.sleep(0.3)
    process.send_signal(stop)
    _, err = process.communicate(timeout=30)
    assert process.returncode == code
    assert err.strip().splitlines()[-1] == line and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_take_arrays_are_plain_numpy(scene: Path, tmp_path: Path) -> None:
    out = tmp_path / "t.npz"
    assert main(["bake", str(scene), "--seconds", "0.05", "--out", str(out), "--quiet"]) == 0
    with np.load(out) as npz:  # no pickles: readable anywhere numpy is
        assert npz["pos.000000"].dtype == np.float32 and npz["pos.000000"].shape == (4, 13, 3)


def test_a_local_bake_never_imports_ray(scene: Path, tmp_path: Path) -> None:
    code = (
        "import sys; from ecs_tentacles.cli import main;"
        f" assert main(['bake', {str(scene)!r}, '--seconds', '0.1', '--quiet',"
        f" '--out', {str(tmp_path / 't.npz')!r}]) == 0;"
        " print(sorted(m for m in sys.modules if m == 'ray' or m.startswith('ray.')))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[-1] == "[]"


def test_resume_without_ray_is_refused(
    scene: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "t.npz"
    assert main(["bake", str(scene), "--seconds", "0.1", "--out", str(out), "--resume"]) == 2
    assert capsys.readouterr().err == (
        "error: argument --resume: only for a --ray bake without --wedge\n"
    )
    assert not out.exists()


def test_lod_options_go_into_the_baked_scene(tmp_path: Path) -> None:
    """`--lod off` / `--focus` bake exactly what a scene saying so bakes (same bytes)."""
    from tests.cli.test_measure import lod_crowd

    crowd = lod_crowd(3)  # budgets: 1 full, 2 reduced
    written = {}
    for name, lod in (
        ("scene", {}),
        ("off", {"enabled": False}),
        ("focus", {"focus": {"center": [-2.0, 2.0], "radius": 0.5}}),  # the third creature
    ):
        variant = json.loads(json.dumps(crowd))
        variant["physics"]["lod"].update(lod)
        written[name] = tmp_path / f"{name}.json"
        written[name].write_text(json.dumps(variant))

    def bake(scene: str, *options: str) -> tuple[str, str]:
        out = tmp_path / "take.npz"
        argv = ["bake", str(written[scene]), "--seconds", "0.1", "--out", str(out), "--quiet"]
        assert main([*argv, *options]) == 0
        take = Take.load(out)
        motion = hashlib.sha256(np.ascontiguousarray(take.pos).tobytes()).hexdigest()
        return take.header["scene_sha256"], motion

    plain = bake("scene")
    assert bake("scene", "--lod", "on") == plain
    off = bake("scene", "--lod", "off")
    assert off == bake("off") and off[1] != plain[1]  # the same scene, another motion
    focus = bake("scene", "--focus=-2,2,0.5")
    assert focus == bake("focus") and focus[1] not in (plain[1], off[1])


def _groomed(guides: int) -> dict[str, object]:
    """SMALL_SCENE's creature with a groom of `guides` guides of 16 points."""
    fur = {"groom": {"count": guides, "points": 16}}
    return {**SMALL_SCENE, "creatures": [{**SMALL_SCENE["creatures"][0], "fur": fur}]}


def test_a_bake_of_fur_at_its_budget_is_not_refused_for_its_length() -> None:
    """250,000 guides of 16 points (the fur budget's 4 million points) are 61 MiB a frame:
    a minute at 60 fps is 220 GiB of guides, which no reader could hold whole. The take
    stores them in chunks of frames and its readers decode a chunk at a time, so the plan
    counts a chunk, not the shot: neither is refused for its length."""
    plan = BakePlan.make(_groomed(250_000), seconds=60)
    assert plan.size_problem() is None
    size = take_size(plan.scene, plan.tracks)
    frame = size.chunked_frame_bytes
    assert frame > 61 * 1024**2  # the guides, the bodies, the suckers, the replay record
    assert size.at_once(plan.frames) < frame + 2 * 1024**2  # one frame a chunk, and the goal


def test_the_take_a_bake_counts_on_is_the_take_it_writes(tmp_path: Path) -> None:
    """What the plan counts before a bake (`export.take_size`) is what the written take
    holds, frame for frame, and never less in all: a bake at the limit reads back."""
    scene = tmp_path / "groomed.json"
    scene.write_text(json.dumps(_groomed(300)))
    bakes = {s: ["bake", str(scene), "--seconds", s, "--quiet", "--out", str(tmp_path / f"{s}.npz")]
             for s in ("0.1", "0.2")}  # fmt: skip
    code = (  # both bakes in one process (it starts and compiles once), each one's exit code
        "from ecs_tentacles.cli import main;"
        f" print([main(argv) for argv in {list(bakes.values())!r}])"
    )
    done = [sys.executable, "-P", "-c", code]
    result = subprocess.run(done, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert result.returncode == 0 and result.stdout.splitlines()[-1] == "[0, 0]", result.stderr
    sizes = []
    for seconds in bakes:
        out = tmp_path / f"{seconds}.npz"
        with zipfile.ZipFile(out) as archive:  # what the reader counts against the limit
            stored = sum(entry.file_size for entry in archive.infolist())
        plan = BakePlan.make(str(scene), seconds=float(seconds))
        counted = take_size(plan.scene, plan.tracks)
        assert Take.load(out).frames == plan.frames
        stored -= plan.frames * 300 * 16 * 12  # the guides' points decode to float32
        assert stored <= counted.total(plan.frames) <= stored + 12 * 1024
        sizes.append((plan.frames, stored, counted.frame_bytes))
    (frames, stored, per_frame), (more, stored_more, _) = sizes
    assert (
        per_frame
        == (stored_more - stored) // (more - frames)
        == 13 * 28 + 3 * 13 + 1 + 300 * 16 * 16 + 33  # 33: the creature's replay record
    )
