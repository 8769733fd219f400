"""Linear blend skinning on the CPU: the reference the exporters and tests compare with.

A vertex v bound to joints a, b with weights wa, wb lands at
(wa * W_a B_a^-1 + wb * W_b B_b^-1) v, where W is a joint's world matrix at the frame
and B its bind matrix (USD's and glTF's rule; the sandbox's vertex shader does the same).
"""

from __future__ import annotations

import numpy as np

from ecs_tentacles.skin.mesh import SkinMesh
from ecs_tentacles.skin.skeleton import Skeleton, transforms


def skinning_matrices(skeleton: Skeleton, rotation: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """(..., J, 4, 4) world * bind^-1 from joint world rotations (..., J, 4) and origins."""
    return transforms(rotation, origin) @ np.linalg.inv(skeleton.bind)


def skin_points(mesh: SkinMesh, matrices: np.ndarray) -> np.ndarray:
    """Skinned vertex positions (V, 3) for one frame's skinning matrices (J, 4, 4)."""
    blended = np.einsum("vk,vkij->vij", mesh.weights, matrices[mesh.joints])
    return np.einsum("vij,vj->vi", blended[:, :3, :3], mesh.positions) + blended[:, :3, 3]
