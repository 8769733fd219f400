"""Mesh templates: closed, outward-wound (culling keeps the near side), lean."""

from __future__ import annotations

import numpy as np
import pytest

from ecs_tentacles.render.meshes import CAPSULE_LODS, CYLINDER_LOD, SPHERE_LOD, Mesh, capsule


@pytest.mark.parametrize("mesh", [*CAPSULE_LODS, SPHERE_LOD, CYLINDER_LOD], ids=str)
def test_triangles_face_outward(mesh: Mesh) -> None:
    p = mesh.positions + mesh.sides[:, None] * [0.5, 0.0, 0.0]  # a capsule of length 1
    a, b, c = (p[mesh.indices[i::3]] for i in range(3))
    winding = np.cross(b - a, c - a)
    area = np.linalg.norm(winding, axis=1)
    solid = area > 1e-12  # pole triangles collapse to nothing
    centroid = (a + b + c) / 3
    outward = np.einsum("ij,ij->i", winding[solid], centroid[solid])
    assert (outward > 0).all()
    assert mesh.indices.max() < len(mesh.positions)


def test_levels_of_detail_get_leaner() -> None:
    near, far = CAPSULE_LODS
    assert far.triangles <= 40 < near.triangles <= 150  # lean: triangles are the cost on a CPU
    assert capsule(10, 3).triangles == near.triangles
