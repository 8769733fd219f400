"""Take tracks: plugins put their own data in takes; takes without goals or fur still work."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export import write
from ecs_tentacles.export.gltf import read_glb
from ecs_tentacles.host import Host
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.record.systems.record import Record
from ecs_tentacles.registry import App
from ecs_tentacles.system import SystemFailure
from ecs_tentacles.take import Take, TakeError
from ecs_tentacles.take.registries import PointsFrame, TakeTracks, TrackSource
from ecs_tentacles.take.tracks import TakeTrack
from ecs_tentacles.world import World
from tests.export.conftest import SMALL_SCENE

# A user's plugin, as a file beside the scene: a beacon over every creature's mantle
# for the first 3 frames, and a curve from each mantle straight up every frame.
BEACONS = textwrap.dedent(
    """
    import numpy as np
    from ecs_tentacles.components import Creature, Transform
    from ecs_tentacles.plugin import Plugin
    from ecs_tentacles.take.registries import CurvesFrame, PointsFrame, TakeTracks, TrackSource
    from ecs_tentacles.take.tracks import TakeTrack

    BEACONS = TakeTrack("beacons", "points", ("beacon_pos", "beacon_live"), "marks", "beacon")
    MASTS = TakeTrack("masts", "curves", ("mast_points", "mast_widths"), "marks", "masts")


    def beacons(world):
        creatures = [] if world.frame >= 3 else list(world.query(Creature))
        return PointsFrame(
            keys=[e for e, _ in creatures],
            creatures=[e for e, _ in creatures],
            order=[0 for _ in creatures],
            positions=[world.component(e, Transform).pos + [0, 0, 0.5] for e, _ in creatures],
            radii=[0.1 for _ in creatures],
        )


    def masts(world):
        creatures = list(world.query(Creature))
        base = np.array([world.component(e, Transform).pos for e, _ in creatures])
        points = base[:, None, :] + np.linspace(0, 1, 3)[None, :, None] * [0, 0, 1]
        return CurvesFrame(points, np.full(points.shape[:2], 0.01), [e for e, _ in creatures])


    class Beacons(Plugin):
        name = "beacons"

        def build(self, app):
            app.add(TakeTracks, self.tracks)

        def tracks(self, world):
            return [TrackSource(BEACONS, beacons), TrackSource(MASTS, masts)]
    """
)


@pytest.fixture
def beacon_scene(tmp_path: Path) -> Path:
    (tmp_path / "beacons.py").write_text(BEACONS)
    scene = {**SMALL_SCENE, "plugins": {"beacons": {"from": "beacons.py"}}}
    path = tmp_path / "beacons.json"
    path.write_text(json.dumps(scene))
    return path


def test_a_user_plugins_tracks_are_baked_into_the_take_and_load_back(
    beacon_scene: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "take.npz"
    argv = ["bake", str(beacon_scene), "--seconds", "0.1", "--out", str(out), "--quiet"]
    assert main([*argv, "--allow-systems"]) == 0
    assert ", 1 goal, 1 beacon; sha256" in capsys.readouterr().out
    take = Take.load(out)
    assert [t["key"] for t in take.header["tracks"]] == ["beacons", "masts"]
    assert take.header["beacons"] == [{"name": "octo/marks/beacon0", "creature": 0, "radius": 0.1}]
    live = take.tracks["beacon_live"]
    assert live.shape == (take.frames, 1) and live[:3].all() and not live[-1].any()
    mantle = take.pos[0, take.body("octo/mantle")]
    np.testing.assert_allclose(take.tracks["beacon_pos"][0], mantle + [0, 0, 0.5], atol=1e-6)
    assert take.tracks["mast_points"].shape == (take.frames, 1, 3, 3)
    assert take.header["masts"] == {"creatures": [0]}
    with np.load(out) as plain:  # still a plain npz: chunks, tracks (declared last), header
        whole = [name for name in plain.files if "." not in name]
        assert whole == ["goal_pos", "goal_active", "beacon_pos", "beacon_live", "header"]
        assert {"mast_points.000000", "mast_widths.000000"} <= set(plain.files)
    write(take, tmp_path / "take.glb")
    document, _ = read_glb((tmp_path / "take.glb").read_bytes())
    assert document["nodes"][0]["name"] == "World"
    pxr = pytest.importorskip("pxr")
    write(take, tmp_path / "take.usda")
    stage = pxr.Usd.Stage.Open(str(tmp_path / "take.usda"))
    beacon = pxr.UsdGeom.Imageable(stage.GetPrimAtPath("/World/octo/octo_marks/octo_beacon0"))
    assert beacon.ComputeVisibility(0) == "inherited"
    assert beacon.ComputeVisibility(take.frames - 1) == "invisible"
    assert stage.GetPrimAtPath("/World/octo/octo_marks/octo_masts").GetTypeName() == "BasisCurves"
    assert stage.GetPrimAtPath("/World/octo/octo_goals/octo_goal0").IsValid()


def test_a_take_with_an_undeclared_or_unsound_track_is_refused(
    beacon_scene: Path, tmp_path: Path
) -> None:
    out = tmp_path / "take.npz"
    argv = ["bake", str(beacon_scene), "--seconds", "0.05", "--out", str(out), "--quiet"]
    assert main([*argv, "--allow-systems"]) == 0
    take = Take.load(out)
    declared = take.header.pop("tracks")
    with pytest.raises(TakeError, match=r"unknown entry 'beacon_pos\.npy'"):
        _save_raw(take, tmp_path / "undeclared.npz")
    take.header["tracks"] = [{**declared[0], "kind": "voxels"}, declared[1]]
    with pytest.raises(TakeError, match=r"header.tracks\[0\].kind: must be one of points"):
        _save_raw(take, tmp_path / "unsound.npz")
    take.header["tracks"] = [{**declared[0], "key": "goals"}, declared[1]]
    with pytest.raises(TakeError, match=r"header.tracks\[0\].key: 'goals' is used twice"):
        _save_raw(take, tmp_path / "twice.npz")


def _save_raw(take: Take, path: Path) -> None:
    """Write every array the take holds, whatever its header says, then load it."""
    from ecs_tentacles.take import write_npz

    arrays = take.arrays()
    arrays.update(take.tracks)
    # a version 1 file: one entry per array, no replay records
    header = {k: v for k, v in take.header.items() if k != "replay"} | {"version": 1}
    arrays = {k: v for k, v in arrays.items() if not k.startswith("replay_")}
    arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
    write_npz(path, arrays)
    Take.load(path)


class BadGoals(Plugin):
    name = "bad_goals"

    def build(self, app: App) -> None:
        app.add(TakeTracks, self.tracks)

    def tracks(self, world: Host) -> list[TrackSource]:
        track = TakeTrack("goals", "points", ("goal_xyz", "goal_on"), "goals", "goal")
        return [TrackSource(track, lambda w: PointsFrame([], [], [], [], []))]


def test_a_standard_track_must_be_declared_as_the_standard_one() -> None:
    world = World.from_scene(SMALL_SCENE)
    world.add_plugin(BadGoals())
    with pytest.raises(SystemFailure, match="take track 'goals' must be declared as"):
        world.add_system(Record())
    world.close()


BARE: dict[str, Any] = {
    **SMALL_SCENE,
    "plugins": {"locomotion": False, "suckers": False, "fur": False},
}


def test_a_world_without_locomotion_or_fur_records_empty_standard_tracks(tmp_path: Path) -> None:
    creature = {"name": "octo", "position": [0, 0], "tentacles": {"count": 3, "links": 4}}
    scene = {**BARE, "creatures": [creature]}  # no goals: the locomotion plugin is off
    world = World.from_scene(scene)
    system = Record()
    world.add_system(system)
    world.step(3)
    take = system.take()
    world.close()
    assert take.header["goals"] == [] and take.header["guides"] is None
    assert "tracks" not in take.header
    assert sorted(n for n in take.tracks if not n.startswith("replay_")) == [
        "goal_active",
        "goal_pos",
    ]
    assert take.tracks["goal_pos"].shape == (0, 3)
    assert take.tracks["goal_active"].shape == (4, 0)
    take.save(tmp_path / "bare.npz")
    loaded = Take.load(tmp_path / "bare.npz")
    np.testing.assert_array_equal(loaded.pos, take.pos)
    write(loaded, tmp_path / "bare.glb")
    assert (tmp_path / "bare.glb").stat().st_size > 0
    pxr = pytest.importorskip("pxr")
    write(loaded, tmp_path / "bare.usda")
    stage = pxr.Usd.Stage.Open(str(tmp_path / "bare.usda"))
    assert stage.GetPrimAtPath("/World/octo/octo_mantle").IsValid()
    assert not stage.GetPrimAtPath("/World/octo/octo_goals").IsValid()
    assert not stage.GetPrimAtPath("/World/octo/octo_fur").IsValid()
