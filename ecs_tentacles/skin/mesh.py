"""One continuous, watertight skinned mesh per creature (bind pose, metres, z up).

How the surface stays one closed 2-manifold:
* The mantle is a lathe about its +z: a bottom pole, rings of a shallow underside, a
  band of rings at the mantle's radius around the tentacle bases, a dome, a top pole.
* Around tentacle k the band and its columns form a k x k block of quads centred on
  the tentacle's base (the grid offsets are r * tan(...), so the block's border seen
  from its centre is 4k equally spaced angles). The block's faces are removed; its
  border loop *is* the tube's first ring, moved onto the tube's circle. No new edges
  are made at the join, so nothing can open.
* The tube follows the thesis taper (radius interpolated between link centres, the
  capsules' radii) with `rings_per_link` rings per link and a hemispherical tip that
  ends in a pole, like the tip capsule's cap.
Triangles wind counter-clockwise seen from outside (normals point outward).

Skin weights: at most two joints per vertex, summing to 1. Mantle vertices follow the
mantle; a tube ring within `blend` x link length of a joint blends the two links (a
smoothstep), the ring at a tentacle's base is the mantle's, other rings are rigid.
UVs are per face corner: around (u) and along (v) each tentacle; the mantle has its
own (u = around, v = bottom to top). Optional sucker discs: a closed flat cylinder on
the underside of each link, rigidly bound to it (extra shells; still closed).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

# numpy and the standard library only when it runs: the Blender add-on runs this file as
# it is (`ecs_tentacles.blender_addon.shared`)
if TYPE_CHECKING:
    from ecs_tentacles.skin.skeleton import Skeleton, SkinLayout, TentacleLayout


class MeshError(ValueError):
    """A creature cannot be meshed (one line naming the creature and the problem)."""


MAX_RINGS_PER_LINK = 64  # past these a mesh only costs memory: 64 x 256 is 16k vertices a link
MAX_SIDES = 256


@dataclass(frozen=True)
class Detail:
    """Level of detail: rings per link, sides (a multiple of 4), tip cap rings, suckers."""

    rings_per_link: int = 4
    sides: int = 12
    cap_rings: int = 3
    suckers: bool = False
    blend: float = 0.35

    def __post_init__(self) -> None:
        if self.rings_per_link < 1:
            raise ValueError(f"rings_per_link: must be >= 1, got {self.rings_per_link}")
        if self.rings_per_link > MAX_RINGS_PER_LINK:
            raise ValueError(
                f"rings_per_link: must be <= {MAX_RINGS_PER_LINK}, got {self.rings_per_link}"
            )
        if self.sides < 4 or self.sides % 4:
            raise ValueError(f"sides: must be a multiple of 4 and >= 4, got {self.sides}")
        if self.sides > MAX_SIDES:
            raise ValueError(f"sides: must be <= {MAX_SIDES}, got {self.sides}")
        if self.cap_rings < 1:
            raise ValueError(f"cap_rings: must be >= 1, got {self.cap_rings}")
        if not 0.0 < self.blend <= 0.5:
            raise ValueError(f"blend: must be in (0, 0.5], got {self.blend}")


@dataclass(frozen=True)
class SkinMesh:
    """A skinned triangle mesh in the bind pose.

    positions/normals (V, 3); faces (T, 3) vertex ids; uv (T, 3, 2) per face corner;
    joints (V, 2) skeleton joint ids and weights (V, 2) summing to 1 (an unused slot has
    weight 0 and joint 0). `rings` (R, sides) vertex ids of every tube ring and `ring_s`
    (R,) their distance from the tentacle base; `ring_tentacle` (R,) which tentacle.
    """

    positions: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    uv: np.ndarray
    joints: np.ndarray
    weights: np.ndarray
    rings: np.ndarray
    ring_s: np.ndarray
    ring_tentacle: np.ndarray


class _Builder:
    """Vertex and face lists grown part by part (each part is array math)."""

    def __init__(self) -> None:
        self.positions: list[np.ndarray] = []
        self.joints: list[np.ndarray] = []
        self.weights: list[np.ndarray] = []
        self.faces: list[np.ndarray] = []
        self.uv: list[np.ndarray] = []
        self.count = 0

    def vertices(self, points: np.ndarray, joints: np.ndarray, weights: np.ndarray) -> np.ndarray:
        points = points.reshape(-1, 3)
        ids = np.arange(self.count, self.count + len(points))
        self.positions.append(points)
        self.joints.append(np.broadcast_to(joints, (len(points), 2)))
        self.weights.append(np.broadcast_to(weights, (len(points), 2)))
        self.count += len(points)
        return ids

    def grid(
        self, ids: np.ndarray, u: np.ndarray, v: np.ndarray, keep: np.ndarray | None = None
    ) -> None:
        """Quads between consecutive rows of `ids` (rows, cols), wrapping around the columns.

        `u` has cols + 1 values (the last closes the wrap), `v` one per row.
        """
        rows, cols = ids.shape
        a = np.arange(rows - 1)[:, None]
        c = np.arange(cols)[None, :]
        c1 = (c + 1) % cols
        corners = [ids[a, c], ids[a, c1], ids[a + 1, c1], ids[a + 1, c]]
        uvs = [(u[c], v[a]), (u[c + 1], v[a]), (u[c + 1], v[a + 1]), (u[c], v[a + 1])]
        mask = np.ones((rows - 1, cols), bool) if keep is None else keep
        for tri in ((0, 1, 2), (0, 2, 3)):
            self.faces.append(np.stack([corners[i][mask] for i in tri], axis=1))
            self.uv.append(
                np.stack(
                    [np.stack(np.broadcast_arrays(*uvs[i]), axis=-1)[mask] for i in tri], axis=1
                )
            )

    def fan(
        self, pole: int, ring: np.ndarray, u: np.ndarray, v: float, pole_v: float, flip: bool
    ) -> None:
        """Triangles from `ring` to `pole`; `ring` runs counter-clockwise about the outward
        pole direction, or clockwise with `flip`."""
        c = np.arange(len(ring))
        first, second = (c + 1, c) if flip else (c, c + 1)
        wrap = len(ring)
        self.faces.append(
            np.stack([ring[first % wrap], ring[second % wrap], np.full(len(c), pole)], axis=1)
        )
        mid = 0.5 * (u[c] + u[c + 1])
        self.uv.append(
            np.stack(
                [
                    np.stack([u[first], np.full(len(c), v)], -1),
                    np.stack([u[second], np.full(len(c), v)], -1),
                    np.stack([mid, np.full(len(c), pole_v)], -1),
                ],
                axis=1,
            )
        )


def smoothstep(x: np.ndarray) -> np.ndarray:
    """0 below 0, 1 above 1, 3x^2 - 2x^3 between."""
    x = np.clip(x, 0.0, 1.0)
    eased: np.ndarray = x * x * (3.0 - 2.0 * x)
    return eased


def hole_offsets(radius: float, k: int) -> np.ndarray:
    """k + 1 grid offsets across a tube base whose border is 4k equally spaced angles."""
    return radius * np.tan(0.25 * np.pi * (2.0 * np.arange(k + 1) / k - 1.0))


def creature_mesh(skeleton: Skeleton, detail: Detail | None = None) -> SkinMesh:
    """The creature's skinned mesh in the bind pose (world space, like `skeleton.bind`)."""
    detail = detail or Detail()
    layout = skeleton.layout
    R, h = layout.mantle_radius, layout.mantle_height
    k = detail.sides // 4
    tentacles = layout.tentacles
    rb = max(float(t.radii[0]) for t in tentacles)
    build = _Builder()

    # mantle rows (rho, z) from the bottom pole up, without the poles
    zb = -0.5 * h - rb
    under = np.array([0.3, 0.6, 0.85])
    band = -0.5 * h + hole_offsets(rb, k)
    alpha = 0.5 * np.pi * np.arange(1, 6) / 6
    top = 0.5 * h + 0.35 * R
    rho = np.concatenate([R * under, np.full(k + 1, R), R * np.cos(alpha)])
    z = np.concatenate(
        [zb + 0.35 * rb * (1 - under**2), band, band[-1] + (top - band[-1]) * np.sin(alpha)]
    )
    first_band = len(under)
    theta, starts = _columns(layout.name, R, k, rb, tentacles)
    cols = len(theta)
    ring_xy = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    points = np.concatenate(
        [rho[:, None, None] * ring_xy, np.broadcast_to(z[:, None, None], (len(z), cols, 1))], -1
    )
    mantle_joint, mantle_weight = np.array([0, 0]), np.array([1.0, 0.0])
    ids = build.vertices(points, mantle_joint, mantle_weight).reshape(len(z), cols)
    bottom = build.vertices(np.array([0.0, 0.0, zb + 0.35 * rb]), mantle_joint, mantle_weight)[0]
    apex = build.vertices(np.array([0.0, 0.0, top]), mantle_joint, mantle_weight)[0]
    u = np.append(theta - theta[0], 2 * np.pi) / (2 * np.pi)
    v = np.linspace(0.0, 1.0, len(z) + 2)
    keep = np.ones((len(z) - 1, cols), bool)
    for start in starts:
        keep[first_band : first_band + k, start : start + k] = False
    build.grid(ids, u, v[1:-1], keep)
    build.fan(bottom, ids[0], u, v[1], 0.0, flip=True)
    build.fan(apex, ids[-1], u, v[-2], 1.0, flip=False)

    rings, ring_s, ring_tentacle = [], [], []
    for t, (tentacle, start) in enumerate(zip(tentacles, starts, strict=True)):
        border = _border(ids[first_band : first_band + k + 1, start : start + k + 1], k)
        made, s = _tube(build, tentacle, border, R, h, detail)
        rings.append(made)
        ring_s.append(s)
        ring_tentacle.append(np.full(len(s), t))

    positions = np.concatenate(build.positions)
    faces = np.concatenate(build.faces)
    used = np.zeros(len(positions), bool)
    used[faces] = True
    remap = np.cumsum(used) - 1
    bind = skeleton.bind[0]
    world = positions[used] @ bind[:3, :3].T + bind[:3, 3]
    faces = remap[faces]
    return SkinMesh(
        positions=world,
        normals=vertex_normals(world, faces),
        faces=faces,
        uv=np.concatenate(build.uv),
        joints=np.concatenate(build.joints)[used],
        weights=np.concatenate(build.weights)[used],
        rings=remap[np.concatenate(rings)],
        ring_s=np.concatenate(ring_s),
        ring_tentacle=np.concatenate(ring_tentacle),
    )


def topology(layout: SkinLayout, detail: Detail | None = None) -> tuple[object, ...]:
    """What the size of `creature_mesh`'s mesh depends on: the detail, each tentacle's
    links and the mantle's columns (where each tentacle's hole starts, and how many in
    all). Two layouts with the same topology give meshes of the same vertex and triangle
    counts (`export.glb_size` counts a crowd's meshes by building one per topology)."""
    detail = detail or Detail()
    k = detail.sides // 4
    rb = max(float(t.radii[0]) for t in layout.tentacles)
    theta, starts = _columns(layout.name, layout.mantle_radius, k, rb, layout.tentacles)
    links = tuple(len(t.lengths) for t in layout.tentacles)
    return (detail, links, tuple(starts), len(theta))


def split_by_uv(mesh: SkinMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices with one UV each, as glTF wants them (a vertex is split where its UVs
    differ): (source vertex, uv) per new vertex, and the triangles on them."""
    corners = mesh.faces.reshape(-1)
    uv = mesh.uv.reshape(-1, 2).astype(np.float32)
    keys = np.concatenate([corners[:, None].astype(np.float64), uv.astype(np.float64)], axis=1)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    return unique[:, 0].astype(np.int64), unique[:, 1:].astype(np.float32), inverse.reshape(-1, 3)


def _columns(
    name: str, R: float, k: int, rb: float, tentacles: list[TentacleLayout]
) -> tuple[np.ndarray, list[int]]:
    """Mantle column angles: k + 1 per tentacle base, then the gap up to the next one."""
    angles = [t.angle for t in tentacles]
    half = [np.arctan(float(t.radii[0]) / R) for t in tentacles]
    spacing = 1.25 * 2.0 * rb / k / R  # radians between gap columns
    theta: list[np.ndarray] = []
    starts: list[int] = []
    for t, tentacle in enumerate(tentacles):
        nxt = (t + 1) % len(tentacles)
        end = angles[nxt] + (2 * np.pi if nxt <= t else 0.0) - half[nxt]
        gap = end - (angles[t] + half[t])
        if gap <= 1e-6:
            raise MeshError(
                f"creature {name}: tentacles t{t} and t{nxt} overlap at the mantle;"
                " the skinned mesh needs room between tentacle bases"
            )
        starts.append(sum(len(a) for a in theta))
        theta.append(angles[t] + np.arctan(hole_offsets(float(tentacle.radii[0]), k) / R))
        quads = max(1, int(np.ceil(gap / spacing)))
        theta.append(np.linspace(angles[t] + half[t], end, quads + 1)[1:-1])
    return np.concatenate(theta), starts


def _border(block: np.ndarray, k: int) -> np.ndarray:
    """The border of a (k + 1, k + 1) block of ids as 4k ids, counter-clockwise seen from
    outside (starting at angle -45 deg: right side up, top leftwards, left down, bottom)."""
    right = block[0:k, k]
    upper = block[k, k:0:-1]
    left = block[k:0:-1, 0]
    lower = block[0, 0:k]
    return np.concatenate([right, upper, left, lower])


def _tube(
    build: _Builder,
    tentacle: TentacleLayout,
    border: np.ndarray,
    R: float,
    h: float,
    detail: Detail,
) -> tuple[np.ndarray, np.ndarray]:
    """Rings along one tentacle (the first is the mantle's border) and its tip; returns the
    ring vertex ids (rings, sides) and each ring's distance from the base."""
    sides = detail.sides
    joints_s = np.concatenate([[0.0], np.cumsum(tentacle.lengths)])
    centres = joints_s[:-1] + 0.5 * tentacle.lengths
    fraction = np.arange(detail.rings_per_link) / detail.rings_per_link
    along = (joints_s[:-1, None] + tentacle.lengths[:, None] * fraction).reshape(-1)
    tip_r = float(tentacle.radii[-1])
    cap = 0.5 * np.pi * np.arange(detail.cap_rings + 1) / (detail.cap_rings + 1)
    s = np.concatenate([along, joints_s[-1] + tip_r * np.sin(cap)])
    radius = np.interp(s, centres, tentacle.radii)
    radius[len(along) :] = tip_r * np.cos(cap)
    phi = -0.25 * np.pi + 2 * np.pi * np.arange(sides) / sides
    c, sn = np.cos(tentacle.angle), np.sin(tentacle.angle)
    axis, side, up = np.array([c, sn, 0.0]), np.array([-sn, c, 0.0]), np.array([0.0, 0.0, 1.0])
    base = np.array([R * c, R * sn, -0.5 * h])
    circle = np.cos(phi)[:, None] * side + np.sin(phi)[:, None] * up
    points = base + s[:, None, None] * axis + radius[:, None, None] * circle
    pair, weight = _ring_weights(s, joints_s, tentacle, detail.blend)
    _move(build, border, points[0])
    ids = np.empty((len(s), sides), np.int64)
    ids[0] = border
    for r in range(1, len(s)):  # one block per ring: each ring has its own two joints
        ids[r] = build.vertices(points[r], pair[r], np.array([1.0 - weight[r], weight[r]]))
    tip_weights = np.array([1.0 - weight[-1], weight[-1]])
    tip = build.vertices(base + (joints_s[-1] + tip_r) * axis, pair[-1], tip_weights)[0]
    total = joints_s[-1] + tip_r
    u = np.arange(sides + 1) / sides
    build.grid(ids, u, s / total)
    build.fan(tip, ids[-1], u, s[-1] / total, 1.0, flip=False)
    if detail.suckers:
        for i, (middle, r) in enumerate(zip(centres, tentacle.radii, strict=True)):
            where = base + middle * axis - 0.8 * r * up
            _disc(build, where, -up, axis, 0.45 * r, 0.35 * r, tentacle.joints[i])
    return ids, s


def _disc(
    build: _Builder,
    centre: np.ndarray,
    normal: np.ndarray,
    across: np.ndarray,
    radius: float,
    height: float,
    joint: int,
) -> None:
    """A closed flat cylinder (a sucker) from `centre` outwards along `normal`, on `joint`."""
    sides = 8
    angle = 2 * np.pi * np.arange(sides) / sides
    other = np.cross(normal, across)
    circle = np.cos(angle)[:, None] * across + np.sin(angle)[:, None] * other
    rows = centre + np.array([0.0, height])[:, None, None] * normal + radius * circle
    joints, weights = np.array([joint, 0]), np.array([1.0, 0.0])
    ids = build.vertices(rows, joints, weights).reshape(2, sides)
    inner = build.vertices(centre, joints, weights)[0]
    outer = build.vertices(centre + height * normal, joints, weights)[0]
    u = np.arange(sides + 1) / sides
    build.grid(ids, u, np.array([0.25, 0.75]))
    build.fan(inner, ids[0], u, 0.25, 0.0, flip=True)
    build.fan(outer, ids[1], u, 0.75, 1.0, flip=False)


def _move(build: _Builder, ids: np.ndarray, points: np.ndarray) -> None:
    """Move existing vertices (the mantle block, which holds every border) to `points`."""
    build.positions[0] = build.positions[0].reshape(-1, 3)
    build.positions[0][ids] = points


def _ring_weights(
    s: np.ndarray, joints_s: np.ndarray, tentacle: TentacleLayout, blend: float
) -> tuple[np.ndarray, np.ndarray]:
    """Per ring: two skeleton joints and the weight of the second."""
    n = len(tentacle.lengths)
    link = np.clip(np.searchsorted(joints_s, s, side="right") - 1, 0, n - 1)
    nearest = np.argmin(np.abs(s[:, None] - joints_s[None, :n]), axis=1)
    d = s - joints_s[nearest]
    lengths = tentacle.lengths
    before = lengths[np.maximum(nearest - 1, 0)]
    width = blend * np.where(nearest == 0, lengths[0], np.minimum(before, lengths[nearest]))
    joints = tentacle.joints
    rigid = np.stack([joints[link], np.zeros_like(link)], axis=1)
    pair = rigid.copy()
    weight = np.zeros(len(s))  # weight of pair[:, 1]
    # base joint: the mantle (joint 0) fades into the first link over one blend width
    base = (nearest == 0) & (d < width)
    pair[base] = np.stack([np.zeros(base.sum(), int), np.full(base.sum(), joints[0])], axis=1)
    weight[base] = smoothstep(d[base] / width[base])
    inner = (nearest > 0) & (np.abs(d) < width)
    pair[inner] = np.stack([joints[nearest[inner] - 1], joints[nearest[inner]]], axis=1)
    weight[inner] = smoothstep((d[inner] + width[inner]) / (2 * width[inner]))
    return pair, weight


def vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals of a triangle mesh."""
    a, b, c = (positions[faces[:, i]] for i in range(3))
    face = np.cross(b - a, c - a)
    normals = np.zeros_like(positions)
    for i in range(3):
        np.add.at(normals, faces[:, i], face)
    unit: np.ndarray = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    return unit
