"""Child hairs blended from the 3 nearest guides: on the skin, above it, weighted."""

from __future__ import annotations

import resource
import subprocess
import sys
from collections.abc import Callable

import numpy as np
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.components import Creature
from ecs_tentacles.fur import child_hairs
from ecs_tentacles.fur.children import layout
from ecs_tentacles.fur.groom import closest_surface_point
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION

SCENE = {
    "version": 1,
    "creatures": [
        {
            "name": "cat",
            "tentacles": {"count": 4, "links": 3},
            "fur": {"preset": "cat", "groom": {"count": 150}, "children": 5},
            "goals": [{"position": [1.0, 0.6]}],
        },
        {
            "name": "hog",
            "position": [-1.5, 0.0],
            "tentacles": {"count": 4, "links": 3},
            "fur": {"preset": "hedgehog", "groom": {"count": 80}, "children": 3},
        },
    ],
}


def test_child_roots_lie_on_the_skin_and_children_stay_above_it(
    make_world: Callable[..., World],
) -> None:
    world = make_world(SCENE)
    world.resource(FurData).controls.lift[:] = 0.0  # guides lying close to the skin: the hard case
    world.step(40)  # crawling and turning: the mantle is not at the origin
    kids = child_hairs(world)
    made = layout(world)
    g = world.resource(FurData).guides
    assert kids.points.shape == (150 * 5 + 80 * 3, 8, 3)
    for f, name in enumerate(("cat", "hog")):
        mine = np.flatnonzero(g.fur_row[made.parent] == f)
        creature = world.component(world.creature(name), Creature)
        radius, height = creature.mantle_radius, creature.mantle_height
        surface, _ = closest_surface_point(made.root[mine], radius, height)
        assert_allclose(made.root[mine], surface, atol=1e-12)  # roots on the skin
        assert (g.fur_row[made.neighbours[mine]] == f).all()  # blended within their fur
        body = int(g.body_row[g.fur_row == f][0])
        pos, quat = world.transforms.pos[body], world.transforms.quat[body]
        points = kids.points[mine].reshape(-1, 3).astype(np.float64)
        local = quat_rotate(np.tile(quat * [1, -1, -1, -1], (len(points), 1)), points - pos)
        assert_allclose(local.reshape(len(mine), 8, 3)[:, 0], made.root[mine], atol=1e-5)
        rho, z = np.hypot(local[:, 0], local[:, 1]), np.abs(local[:, 2])
        inside = (rho < radius - 1e-5) & (z < height / 2 - 1e-5)
        assert not inside.any()  # nothing under the skin
    assert_allclose(made.weights.sum(axis=1), 1.0)
    # the 3 nearest guides of each child, by brute force
    cat = np.flatnonzero(g.fur_row == 0)
    d = np.linalg.norm(made.root[:750, None] - g.root[cat][None], axis=2)
    assert_array_equal(np.sort(made.neighbours[:750], axis=1), np.sort(cat[np.argsort(d)[:, :3]]))


def test_children_blend_their_guides_offsets(make_world: Callable[..., World]) -> None:
    still = [{k: v for k, v in c.items() if k != "goals"} for c in SCENE["creatures"]]
    world = make_world({**SCENE, "creatures": still}, plugins=NO_LOCOMOTION)
    world.resource(FurData).controls.lift[:] = 0.8  # standing up: nothing to clamp
    world.step(3)
    made = layout(world)
    kids = child_hairs(world).points
    curves, roots = world.resource(FurData).curves, world.resource(FurData).frames[:, 3]
    offsets = curves[made.neighbours] - roots[made.neighbours][:, :, None]
    blended = np.einsum("mk,mkpd->mpd", made.weights * made.scale[:, None], offsets)
    quat = world.transforms.quat[made.body]
    normal = quat_rotate(quat, made.normal)
    below = np.minimum(np.einsum("mpd,md->mp", blended, normal), 0.0)
    assert 0 < (below < 0).any(axis=1).sum() < 0.05 * len(kids)  # a few at the cap's rim
    assert_allclose(kids - kids[:, :1], blended - below[..., None] * normal[:, None], atol=2e-6)
    assert layout(world) is made  # cached until the bind pose changes
    world.resource(FurData).touch()
    assert layout(world) is not made
    colours = child_hairs(world).colour[:, :3]
    base = world.resource(FurData).sets.colour[
        g_fur := world.resource(FurData).guides.fur_row[made.parent]
    ]
    ratio = colours / base.astype(np.float32)
    assert ratio.std() > 0.02 and (ratio > 0.79).all() and (ratio < 1.16).all()  # jitter
    assert len(set(g_fur.tolist())) == 2


BIG = """
from ecs_tentacles.fur import child_hairs
from ecs_tentacles.world import World

fur = {"groom": {"count": 50_000, "points": 4}, "children": 2}
creature = {"name": "c", "tentacles": {"count": 3, "links": 2}, "fur": fur}
world = World.from_scene({"version": 1, "creatures": [creature]})
print(len(child_hairs(world).points))
"""
MEMORY = 1536 * 1024**2  # bytes of address space for BIG (a brute force takes 2.3 GiB at once)


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def test_the_children_of_a_big_groom_are_set_up_in_memory_linear_in_them() -> None:
    """100,000 children of 50,000 guides: their nearest guides within 1.5 GB of address
    space in all, in about a second (comparing every child with every guide took 2.3 GiB
    at once, and time in children x guides)."""
    result = subprocess.run(
        [sys.executable, "-P", "-c", BIG],
        capture_output=True, text=True, timeout=120, preexec_fn=_limit_memory,
    )  # fmt: skip
    assert (result.returncode, result.stdout) == (0, "100000\n"), result.stderr[-500:]
