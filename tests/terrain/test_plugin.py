"""The terrain plugin as a scene uses it: creatures rest on the surface, goals snap to it,
suckers grip slopes and obstacles, and bad terrain input is one line naming the field."""

from __future__ import annotations

import json
import pathlib
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from PIL import Image

from ecs_tentacles.cli import main
from ecs_tentacles.ground import ground_of
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.physics.tiers import KINEMATIC, REDUCED
from ecs_tentacles.scene.construction import creature_layout
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import bundled_scene
from ecs_tentacles.terrain.ground import TerrainGround
from ecs_tentacles.terrain.scene_ground import build_ground
from ecs_tentacles.terrain.shapes import Solid
from ecs_tentacles.world import World

ROCKY = {
    "heightfield": {
        "size": [12, 12],
        "resolution": 64,
        "height": 0.5,
        "noise": {"seed": 3, "scale": 4.0, "octaves": 3},
    },
    "obstacles": [
        {"shape": "box", "position": [3, 0, 0.3], "size": [0.3, 4, 0.6]},
        {"shape": "cylinder", "position": [-3, 2, 0.4], "radius": 0.5, "height": 0.8},
        {"shape": "sphere", "position": [0, -3, 0], "radius": 0.7},
    ],
}


def scene(
    terrain: dict[str, Any], *positions: list[float], goal: list[float] | None = None
) -> dict[str, Any]:
    creatures = [{"name": f"c{i}", "position": p} for i, p in enumerate(positions)]
    if goal is not None:
        creatures[0]["goals"] = [{"position": goal}]
    return {"version": 1, "terrain": terrain, "creatures": creatures}


def _bodies_clearance(world: World, spec: dict[str, Any]) -> float:
    """The smallest gap (m) between any link capsule's axis points and the ground, less
    the link's radius, at build."""
    starts, ends, radii = creature_layout(spec, ground_of(world)).capsules()
    ground = ground_of(world)
    gaps = [ground.distance(p)[1:] - radii[1:] for p in (starts, ends, 0.5 * (starts + ends))]
    return float(np.min(gaps))


def test_creatures_start_on_the_surface_and_settle_without_faults(
    make_world: Callable[..., World],
) -> None:
    world = make_world(scene(ROCKY, [0, 0], [-1.5, 1.2], [1.2, 2.5], [-1.0, -1.5]))
    for spec in world.scene["creatures"]:  # type: ignore[index]
        gap = _bodies_clearance(world, spec)
        assert 0.0 <= gap < 0.02, spec["name"]  # resting on it, not inside, not floating
    for _ in range(60):
        world.step()
    assert world.physics.health.recoveries == 0
    deepest = min(float(b.deepest.min()) for b in world.physics.batches)
    assert deepest > -0.005  # never sunk more than 5 mm into the terrain
    mantles = world.transforms.pos[world.creatures.mantle_row]
    assert (mantles[:, 2] - ground_of(world).height(mantles[:, :2]) > 0.0).all()


def test_goals_snap_to_the_surface(make_world: Callable[..., World]) -> None:
    world = make_world(scene(ROCKY, [0, 0], goal=[1.5, 1.0]))
    goal = world.resource(GoalBook).positions(world.creature("c0"))[0]
    assert goal[2] == pytest.approx(ground_of(world).height(goal[None, :2])[0])
    assert goal[2] > 0.01  # the noise is not flat there


def test_heights_rows_run_along_y_from_minus_y(make_world: Callable[..., World]) -> None:
    """A ramp given as `heights` (rising along +y): a creature placed high sits high."""
    rows = [[0.1 * r] * 5 for r in range(9)]  # 0 at y = -4, 0.8 at y = +4
    world = make_world(scene({"heightfield": {"size": [4, 8], "heights": rows}}, [0, 2.0]))
    mantle = world.transforms.pos[world.creatures.mantle_row[0]]
    assert mantle[2] > 0.55  # the surface under y = 2 is 0.6 m up


def test_a_16_bit_image_gives_the_heights(tmp_path: pathlib.Path) -> None:
    pixels = np.zeros((5, 5), dtype=np.uint16)
    pixels[0, :] = 65535  # the picture's top row: +y
    Image.fromarray(pixels).save(tmp_path / "hill.png")
    terrain = {"heightfield": {"size": [4, 4], "image": "hill.png", "height": 0.4}}
    (tmp_path / "s.json").write_text(json.dumps(scene(terrain, [0, 0])))
    world = World.from_scene(tmp_path / "s.json")
    try:
        ground = ground_of(world)
        assert ground.height(np.array([[0.0, 2.0], [0.0, -2.0]])).tolist() == pytest.approx(
            [0.4, 0.0]
        )
    finally:
        world.close()


def test_suckers_grip_a_slope(make_world: Callable[..., World]) -> None:
    """On a 12 degree slope the suckers attach where the tips touch it, well above z = 0."""
    rise = float(np.tan(np.radians(12.0)))
    rows = [[rise * (x - 3.0) + 3.0 * rise for x in np.linspace(0, 6, 13)] for _ in range(5)]
    world = make_world(
        scene({"heightfield": {"size": [6, 4], "heights": rows}}, [0, 0], goal=[1.5, 0])
    )
    anchors: list[np.ndarray] = []
    world.events.on("sucker_attached", lambda **kw: anchors.append(kw["anchor"]))
    for _ in range(240):
        world.step()
    assert len(anchors) >= 4
    anchors_ = np.array(anchors)
    ground = ground_of(world)
    assert (anchors_[:, 2] > 0.3).all()  # on the slope, far above the old plane
    assert np.abs(ground.distance(anchors_)).max() < 0.01  # on its surface


def _validate(
    tmp_path: pathlib.Path, data: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> tuple[int, str]:
    """`ecs-tentacles run SCENE --frames 1` in this process: (exit code, stderr)."""
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    code = main(["run", str(path), "--frames", "1", "--quiet"])
    return code, capsys.readouterr().err


BAD: dict[str, tuple[dict[str, Any], str]] = {
    "image missing": (
        {"heightfield": {"size": [4, 4], "image": "nowhere.png"}},
        "terrain.heightfield.image: nowhere.png: no such file in the scene's folder",
    ),
    "mesh escaping the folder": (
        {"obstacles": [{"shape": "mesh", "file": "../rock.obj", "position": [3, 0, 0]}]},
        "terrain.obstacles[0].file: ../rock.obj: must be a file in the scene's folder",
    ),
    "resolution 1": (
        {"heightfield": {"size": [4, 4], "resolution": 1, "noise": {}}},
        "terrain.heightfield.resolution: must be in [3, 1024], got 1",
    ),
    "two sources": (
        {"heightfield": {"size": [4, 4], "noise": {}, "image": "x.png"}},
        "terrain.heightfield: give exactly one of noise, image or heights (has: noise, image)",
    ),
    "a sphere without radius": (
        {"obstacles": [{"shape": "sphere", "position": [3, 0, 0]}]},
        "terrain.obstacles[0]: a sphere needs 'radius'",
    ),
    "a creature inside a rock": (
        {"obstacles": [{"shape": "sphere", "position": [0.5, 0, 0], "radius": 0.3}]},
        "creatures[0].position: c0 is inside terrain.obstacles[0]; move it or the obstacle",
    ),
}


@pytest.mark.parametrize("case", BAD, ids=list(BAD))
def test_bad_terrain_is_one_line_naming_the_field(
    tmp_path: pathlib.Path, case: str, capsys: pytest.CaptureFixture[str]
) -> None:
    terrain, message = BAD[case]
    (tmp_path.parent / "rock.obj").write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
    )
    code, err = _validate(tmp_path, scene(terrain, [0, 0]), capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines


def test_nan_heights_and_a_hundred_thousand_obstacles_are_refused(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "nan.json"
    rows = [[0.0, 0.0, 0.0], [0.0, float("nan"), 0.0], [0.0, 0.0, 0.0]]
    data = scene({"heightfield": {"size": [4, 4], "heights": rows}}, [0, 0])
    path.write_text(json.dumps(data))  # Python writes NaN; JSON has no such number
    assert main(["validate", str(path)]) == 2
    assert "NaN is not valid JSON" in capsys.readouterr().err
    with pytest.raises(
        SceneError, match=r"terrain\.heightfield\.heights\[1\]\[1\]: must be a finite"
    ):
        World.from_scene(data)  # a dict from a script can hold one
    many = [{"shape": "sphere", "position": [50, 50, 0], "radius": 0.1}] * 100_000
    code, err = _validate(tmp_path, scene({"obstacles": many}, [0, 0]), capsys)
    assert code == 2
    assert "terrain.obstacles: must have at most 1000 items" in err, err[:300]


def test_a_concave_mesh_is_split_into_convex_pieces(
    tmp_path: pathlib.Path, make_world: Callable[..., World]
) -> None:
    import trimesh

    arch = trimesh.util.concatenate(
        [
            trimesh.creation.box(
                (0.3, 1.0, 1.0), trimesh.transformations.translation_matrix((x, 0, 0.5))
            )
            for x in (-0.6, 0.6)
        ]
        + [
            trimesh.creation.box(
                (1.5, 1.0, 0.3), trimesh.transformations.translation_matrix((0, 0, 1.15))
            )
        ]
    )
    arch.export(tmp_path / "arch.obj")
    terrain = {
        "obstacles": [{"shape": "mesh", "file": "arch.obj", "position": [3, 0, 0], "scale": 1.0}]
    }
    world = make_world(scene(terrain, [0, 0]), scene_dir=tmp_path)
    solid = ground_of(world).solids[0]
    assert len(solid.pieces) >= 3  # two legs and a lintel, not one hull
    # the hollow under the arch stays hollow: its middle is outside every piece
    assert solid.signed_distance(np.array([[3.0, 0.0, 0.4]]))[0] > 0.2


def test_kinematic_creatures_are_draped_over_the_terrain(make_world: Callable[..., World]) -> None:
    """Gait clips are recorded on the plane; on terrain every replayed body is raised by
    the ground under it (tips on the ground), and one about to meet a rock is simulated
    (reduced: contact promotes to a physical tier, full is for heroes)."""
    hills = {"heightfield": ROCKY["heightfield"]}
    rock = {"shape": "sphere", "position": [-1.5, -3.0, 0.2], "radius": 0.4}
    data = scene({**hills, "obstacles": [rock]}, [0, 0], [3.0, 2.0], [-3.0, 2.5], [-1.5, -1.9])
    data["physics"] = {"lod": {"full": 0, "reduced": 0, "hold_seconds": 0.1}}
    world = make_world(data)
    for _ in range(20):
        world.step()
    tiers = world.physics.tier
    assert (tiers == KINEMATIC).sum() == 3 and tiers[3] == REDUCED  # the one by the rock
    ground = ground_of(world)
    for index in np.flatnonzero(tiers == KINEMATIC).tolist():
        batch, row = world.physics.roster.locate(index)
        pos, _ = batch.poses(row)  # as the replay placed it (written into the store)
        above = pos[:, 2] - ground.height(pos[:, :2])
        assert above.min() > -0.005 and np.median(above) < 0.08  # on it, not in or over it


def test_crowd_on_rocky_terrain_is_a_valid_scene(tmp_path: pathlib.Path) -> None:
    out = tmp_path / "crowd.json"
    assert main(["crowd", "9", "--terrain", "rocky", "--out", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["terrain"]["heightfield"]["noise"]["seed"] == 0
    assert main(["run", str(out), "--frames", "30", "--strict", "--quiet"]) == 0


def test_a_3d_position_is_checked_against_the_terrain_not_z_0(
    make_world: Callable[..., World],
) -> None:
    sunk = {"heightfield": {"size": [4, 4], "heights": [[0.5] * 3] * 3}}
    with pytest.raises(
        SceneError, match=r"creatures\[0\].position: c0 starts \d+ mm inside the terrain"
    ):
        World.from_scene(scene(sunk, [0, 0, 0.3]))
    low = {"heightfield": {"size": [4, 4], "heights": [[-0.5] * 3] * 3}}
    world = make_world(scene(low, [0, 0, -0.45]))  # below z = 0, above the ground there
    assert world.transforms.pos[world.creatures.mantle_row[0], 2] < 0.0


def test_past_the_heightfields_edge_the_ground_goes_on_at_its_lowest_height(
    make_world: Callable[..., World],
) -> None:
    rows = [[0.2 + 0.01 * (r % 2)] * 7 for r in range(7)]  # 0.2-0.21 m up, 3 m across
    world = make_world(
        scene({"heightfield": {"size": [3, 3], "heights": rows}}, [1.1, 0], goal=[3.5, 0])
    )  # 0.4 m in from the edge: over it at about 5 s, 1.8 m at about 9 s
    ground = ground_of(world)
    assert ground.height(np.array([[5.0, 0.0]]))[0] == pytest.approx(0.2)
    while world.time < 14.0:
        world.step()
    mantle = world.transforms.pos[world.creatures.mantle_row[0]]
    assert mantle[0] > 1.8  # it crawled off the edge
    assert mantle[2] > 0.2  # onto the plane beyond, not down forever


def _above_ground(world: World) -> np.ndarray:
    """Per obstacle, how far its top rises above the ground under its centre (m)."""
    ground = ground_of(world)
    assert ground.heightfield is not None
    centres = np.array([solid.position[:2] for solid in ground.solids])
    tops = np.array([s.top(c[None])[0] for s, c in zip(ground.solids, centres, strict=True)])
    return tops - ground.heightfield.height(centres)


def _footprint(solid: Solid, ground: TerrainGround) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Over the points (k, 2) a 4 cm grid puts under `solid` (2 cm made this test 35 s
    once the rocky preset had a rock per 1.5 creatures): its lowest and highest point on
    each vertical line there and the ground's height. The lowest is the last of 401
    depths (1 cm or finer, down from the top) inside the solid, found as the full scan
    would on lines whose inside runs on from the top (every convex piece's does): every
    20th depth first, then the 20 after the last of those inside."""
    side = np.arange(-solid.bound, solid.bound + 0.04, 0.04)
    xy = solid.position[:2] + np.stack(np.meshgrid(side, side), axis=-1).reshape(-1, 2)
    top = solid.top(xy)
    xy, top = xy[np.isfinite(top)], top[np.isfinite(top)]
    depth = np.linspace(0.0, 2.0 * solid.bound, 401)

    def last_inside(steps: np.ndarray) -> np.ndarray:
        """Per line, the last of its depth indices `steps` (k, m) inside the solid."""
        z = top[:, None] - depth[steps]
        points = np.column_stack([np.repeat(xy, steps.shape[1], axis=0), z.ravel()])
        inside = solid.signed_distance(points).reshape(z.shape) <= 1e-9
        return steps[np.arange(len(xy)), steps.shape[1] - 1 - np.argmax(inside[:, ::-1], axis=1)]

    coarse = last_inside(np.broadcast_to(np.arange(0, 401, 20), (len(xy), 21)))
    fine = np.minimum(coarse[:, None] + np.arange(21), 400)
    return top - depth[last_inside(fine)], top, ground.height(xy)


RockyScenes = list[tuple[str, dict[str, Any], Any]]


@pytest.fixture(scope="module")
def rocky_scenes(tmp_path_factory: pytest.TempPathFactory) -> RockyScenes:
    """rocky_shore and `crowd N --terrain rocky` for a small and a large crowd: (name,
    scene, its folder); read only."""
    shore = bundled_scene("rocky_shore")
    made = [("rocky_shore", json.loads(shore.read_text()), shore.parent)]
    tmp_path = tmp_path_factory.mktemp("rocky")
    for count in (40, 256):
        out = tmp_path / f"crowd{count}.json"
        assert main(["crowd", str(count), "--terrain", "rocky", "--out", str(out)]) == 0
        made.append((f"crowd {count}", json.loads(out.read_text()), tmp_path))
    return made


def test_rocks_stand_on_the_terrain_not_in_it(rocky_scenes: RockyScenes) -> None:
    """rocky_shore's ledge was 0.13 m under the surface, and 5 of 6 rocks of `crowd 40
    --terrain rocky` had their tops below the ground (of 34 with 256 creatures, 8 stuck
    out more than 5 cm): the ground read as plain sand. Every obstacle a scene does not
    bury on purpose (`on_ground`: false) now rests on the ground, its lowest point at
    or under the lowest ground beneath it (no gap under a side), and rises 5 cm or more
    above the highest ground beneath it (seen from any side)."""
    for name, scene, folder in rocky_scenes:
        terrain = scene["terrain"]
        ground = build_ground(terrain, folder)
        standing = [o.get("on_ground", True) for o in terrain["obstacles"]]
        assert len(ground.solids) == len(standing) >= 4, name
        for k, solid in enumerate(ground.solids):
            if not standing[k]:
                continue
            lowest, top, under = _footprint(solid, ground)
            assert lowest.min() <= under.min() + 0.005, f"{name}: obstacle {k} floats"
            assert top.max() - under.max() >= 0.05, f"{name}: obstacle {k} is buried"


def test_rocky_ground_has_relief_an_artist_notices(rocky_scenes: RockyScenes) -> None:
    """The heightfield rises and falls 0.5 m or more where the creatures are: twice the
    tallest mantle a generated crowd has (0.25 m), so from a camera at a creature's
    height a hill hides a creature behind it (the preset had 0.4 m, rocky_shore 0.47 m
    where its creatures are)."""
    for name, scene, folder in rocky_scenes:
        field = build_ground(scene["terrain"], folder).heightfield
        assert field is not None
        starts = np.array([c["position"][:2] for c in scene["creatures"]])
        low, high = starts.min(axis=0), starts.max(axis=0)
        xs, ys = (np.linspace(low[i], high[i], 200) for i in range(2))
        heights = field.height(np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2))
        assert heights.max() - heights.min() >= 0.5, name


def test_on_ground_false_measures_z_from_zero_and_the_plane_is_unchanged() -> None:
    rock = {"shape": "sphere", "position": [-1.5, -3.0, 0.0], "radius": 0.2}
    buried = {**rock, "on_ground": False}
    hills = {"heightfield": ROCKY["heightfield"]}
    sunk = scene({**hills, "obstacles": [rock, buried]}, [3.0, 3.0])
    with World.from_scene(sunk) as world:
        standing, under = _above_ground(world)
        assert standing == pytest.approx(0.2) and under < 0.2
        field = ground_of(world).heightfield
        assert field is not None
        height = field.height(np.array([[-1.5, -3.0]]))[0]
        assert under == pytest.approx(0.2 - height)
    with World.from_scene(scene({"obstacles": [rock]}, [3.0, 3.0])) as world:
        assert ground_of(world).solids[0].position.tolist() == [-1.5, -3.0, 0.0]
