"""physics.reduced_body: a tentacle's links are joined in consecutive groups, about half as
many and at least 3, and a joined link is as long, as heavy and bends as far as its
links together."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.components import Link
from ecs_tentacles.physics.reduced_body import _capsule_volume, _joined, groups


@pytest.mark.parametrize("links", range(1, 65))
def test_every_link_is_in_one_group_in_order_half_as_many_and_at_least_three(links: int) -> None:
    parts = groups(links)
    np.testing.assert_array_equal(np.concatenate(parts), np.arange(links))
    assert all(len(p) >= 1 for p in parts)
    assert len(parts) == (links if links <= 3 else max(3, -(-links // 2)))
    assert max(len(p) for p in parts) - min(len(p) for p in parts) <= 1  # as even as can be


def test_a_joined_link_is_as_long_and_heavy_as_its_links_and_bends_as_far() -> None:
    links = [
        Link(0, i, length=0.07 * s, radius=0.025 * s, scale=s, density=1000.0,
             joint_limit=0.5, twist=True)
        for i, s in enumerate((1.0, 0.9, 0.8))
    ]  # fmt: skip
    joined = _joined(links, twist=False)
    assert joined.length == pytest.approx(sum(lk.length for lk in links))
    mass = sum(lk.density * _capsule_volume(lk.radius, lk.length) for lk in links)
    assert joined.density * _capsule_volume(joined.radius, joined.length) == pytest.approx(mass)
    assert min(lk.radius for lk in links) < joined.radius < max(lk.radius for lk in links)
    assert joined.joint_limit == pytest.approx(1.5) and not joined.twist
    assert _joined(links * 3, twist=True).joint_limit == pytest.approx(np.pi)  # at most half a turn
