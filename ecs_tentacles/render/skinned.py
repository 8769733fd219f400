"""Skinned creatures in the sandbox: every creature's mesh in one buffer, one draw call.

The meshes are `ecs_tentacles.skin.mesh` creature meshes (the ones the exporters write),
built once per world in each creature's mantle frame and concatenated; each vertex
names two joints of one palette shared by all creatures. Per frame one numpy pass
turns the body poses into the palette (a 3 x 4 world * bind^-1 matrix per joint) and
one upload puts it in a float texture (512 joints a row); the vertex shader
(`shaders.SKINNED_VERTEX`)
blends the vertex's two joints. However many creatures, that is one draw call.

Each creature is meshed at three levels of detail (`DETAILS`): the sandbox's; a coarse
one (a ring per link, eight sides: under a third of the triangles) for creatures the
camera sees smaller than `COARSE_PIXELS` across, where the difference is under a pixel
or two; and a tiny one (four sides: about half the coarse triangles) under
`TINY_PIXELS`, where a tentacle is a few pixels wide. The level is chosen per creature
each frame (`choose_detail`), and the one draw call becomes one `glMultiDrawElements`
over each creature's chosen index range: a crowd framed whole costs what its pixels
need, not what a close-up does. (In software GL a triangle costs about as much as the
pixels it covers: 64 creatures framed whole cover 23,500 pixels with 139,000 coarse
triangles, 15 of a 48 ms frame.)
"""

from __future__ import annotations

import ctypes
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from pyglet import gl

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.render.gpu import FLOAT, _attribute, _buffer, _upload, _vertex_array
from ecs_tentacles.skin.mesh import Detail, MeshError, SkinMesh, creature_mesh
from ecs_tentacles.skin.skeleton import Skeleton, build_skeleton, quat_matrix, skin_layout

if TYPE_CHECKING:
    from ecs_tentacles.world import World

SANDBOX_DETAIL = Detail(rings_per_link=3, sides=12, cap_rings=2)
COARSE_DETAIL = Detail(rings_per_link=1, sides=8, cap_rings=1)
TINY_DETAIL = Detail(rings_per_link=1, sides=4, cap_rings=1)
DETAILS = (SANDBOX_DETAIL, COARSE_DETAIL, TINY_DETAIL)
COARSE_PIXELS = 160.0  # a creature whose reach spans fewer pixels than this is drawn coarse
TINY_PIXELS = 100.0  # ... and fewer than this, tiny
VERTEX_FLOATS = 3 + 3 + 3 + 2 + 1  # position, normal, colour, two joints, second weight
ROW_JOINTS = 512  # joints per palette texture row (the shader's `j % 512`)
PALE = np.array([0.96, 0.86, 0.78])  # the underside of a tentacle


def world_skeleton(world: World, entity: int) -> Skeleton:
    """A creature's skeleton from its components, bound with the mantle at the origin;
    its `bodies` are Transform store rows."""
    creature = world.component(entity, Creature)
    tentacles, rows = [], [world.component(entity, Transform).row]
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        links = [world.component(e, Link) for e in tentacle.links]
        tentacles.append(
            (tentacle.base_angle, [link.length for link in links], [link.radius for link in links])
        )
        rows.extend(world.component(e, Transform).row for e in tentacle.links)
    layout = skin_layout(creature.name, creature.mantle_radius, creature.mantle_height, tentacles)
    return build_skeleton(layout, np.array(rows))


def vertex_colours(mesh: SkinMesh, skeleton: Skeleton, colour: np.ndarray) -> np.ndarray:
    """The creature's colour, darker toward the tentacle tips, pale underneath."""
    depth = np.zeros(len(skeleton.names))
    for tentacle in skeleton.layout.tentacles:
        depth[tentacle.joints] = np.arange(len(tentacle.joints)) / max(len(tentacle.joints) - 1, 1)
    shade = 1.0 - 0.35 * (mesh.weights * depth[mesh.joints]).sum(axis=1)
    base = np.clip(colour * shade[:, None] + 0.08 * (1 - shade[:, None]), 0.0, 1.0)
    on_tube = (mesh.joints[:, 0] > 0) | (mesh.weights[:, 1] > 0)
    underside = np.clip(-mesh.normals[:, 2], 0.0, 1.0) ** 2 * on_tube
    shaded: np.ndarray = base + 0.55 * underside[:, None] * (PALE - base)
    return shaded


class SkinnedCreatures:
    """GPU buffers for all creatures' skinned meshes and their joint palette."""

    def __init__(self) -> None:
        self.vao = _vertex_array()
        gl.glBindVertexArray(self.vao)
        self.vertices = _buffer()
        self.vertex_capacity = [0]
        _upload(gl.GL_ARRAY_BUFFER, self.vertices, np.zeros((1, VERTEX_FLOATS), np.float32), [0])
        stride = VERTEX_FLOATS * FLOAT
        for location, (size, offset) in enumerate(((3, 0), (3, 3), (3, 6), (2, 9), (1, 11))):
            _attribute(location, size, stride, offset)
        self.indices = _buffer()
        self.index_capacity = [0]
        gl.glBindVertexArray(0)
        self.palette_buffer = _buffer()
        self.palette_capacity = [0]
        _upload(
            gl.GL_TEXTURE_BUFFER,
            self.palette_buffer,
            np.zeros(12, np.float32),
            self.palette_capacity,
        )
        texture = gl.GLuint()
        gl.glGenTextures(1, ctypes.byref(texture))
        self.texture = texture.value
        self.first = np.zeros((len(DETAILS), 0), np.int64)  # per level, per creature: byte offset
        self.counts = np.zeros((len(DETAILS), 0), np.int32)  # ... and index count
        self.mantle_rows = np.zeros(0, np.int64)  # per creature: its mantle's store row
        self.reach = np.zeros(0)  # per creature: mantle radius + its longest tentacle (m)
        self.level = np.zeros(0, np.int64)  # per creature: the level it is drawn at
        self.rows = np.zeros(0, np.int64)
        self.offset = np.zeros(0)
        self.inverse_bind = np.zeros((0, 4, 4))
        self.creatures: list[int] = []  # entities drawn skinned
        # kept across rebuilds: each creature's skeleton (and its mantle row then), and
        # each body shape's mesh (None: it cannot be meshed)
        self._skeletons: dict[int, tuple[Skeleton, int]] = {}
        self._meshes: dict[tuple[object, ...], SkinMesh | None] = {}

    def forget(self, creature: int) -> None:
        """Creature `creature` was despawned: drop its skeleton."""
        self._skeletons.pop(creature, None)

    def forget_all(self) -> None:
        """Another world: nothing of the last one's creatures is kept."""
        self._skeletons.clear()

    def _skeleton(self, world: World, entity: int) -> Skeleton:
        """`world_skeleton`, kept per creature: its body rows move with its mantle's (a
        creature's rows stay together whatever is removed around them)."""
        mantle = world.component(entity, Transform).row
        kept = self._skeletons.get(entity)
        if kept is None:
            skeleton = world_skeleton(world, entity)
            self._skeletons[entity] = (skeleton, mantle)
            return skeleton
        skeleton, then = kept
        if then == mantle:
            return skeleton
        return replace(skeleton, bodies=skeleton.bodies + (mantle - then))

    def build(self, world: World, entities: list[int], colours: dict[int, np.ndarray]) -> None:
        """Mesh every creature that can be meshed (others stay capsules: `self.creatures`)."""
        parts, indices = [], []
        rows, offsets, binds = [], [], []
        first, counts, mantles, reach = [], [], [], []
        first_vertex = first_joint = first_index = 0
        self.creatures = []
        for entity in entities:
            skeleton = self._skeleton(world, entity)
            meshes = [self._mesh(skeleton, level) for level in range(len(DETAILS))]
            if any(mesh is None for mesh in meshes):
                continue  # tentacle bases overlap: this one keeps its capsules
            starts, sizes = [], []
            for mesh in meshes:
                assert mesh is not None
                data = np.empty((len(mesh.positions), VERTEX_FLOATS), np.float32)
                data[:, 0:3] = mesh.positions
                data[:, 3:6] = mesh.normals
                data[:, 6:9] = vertex_colours(mesh, skeleton, colours[entity])
                data[:, 9:11] = mesh.joints + first_joint
                data[:, 11] = mesh.weights[:, 1]
                parts.append(data)
                indices.append(mesh.faces.reshape(-1) + first_vertex)
                starts.append(first_index)
                sizes.append(mesh.faces.size)
                first_vertex += len(mesh.positions)
                first_index += mesh.faces.size
            first.append(starts)
            counts.append(sizes)
            rows.append(skeleton.bodies)
            offsets.append(skeleton.offset)
            binds.append(skeleton.bind)
            mantles.append(skeleton.bodies[0])
            layout = skeleton.layout
            longest = max((float(t.lengths.sum()) for t in layout.tentacles), default=0.0)
            reach.append(layout.mantle_radius + longest)
            first_joint += len(skeleton.names)
            self.creatures.append(entity)
        levels = len(DETAILS)
        self.first = (np.array(first, np.int64).reshape(-1, levels).T * 4).copy()  # bytes
        self.counts = np.array(counts, np.int32).reshape(-1, levels).T.copy()
        self.mantle_rows = np.array(mantles, np.int64)
        self.reach = np.array(reach)
        self.level = np.zeros(len(self.creatures), np.int64)
        vertex_data = np.vstack(parts) if parts else np.zeros((0, VERTEX_FLOATS), np.float32)
        index_data = (
            np.concatenate(indices).astype(np.uint32) if indices else np.zeros(0, np.uint32)
        )
        gl.glBindVertexArray(self.vao)
        _upload(gl.GL_ARRAY_BUFFER, self.vertices, vertex_data, self.vertex_capacity)
        _upload(gl.GL_ELEMENT_ARRAY_BUFFER, self.indices, index_data, self.index_capacity)
        gl.glBindVertexArray(0)
        self.rows = np.concatenate(rows) if rows else np.zeros(0, np.int64)
        self.offset = np.concatenate(offsets) if offsets else np.zeros(0)
        self.inverse_bind = np.linalg.inv(np.concatenate(binds)) if binds else np.zeros((0, 4, 4))

    def _mesh(self, skeleton: Skeleton, level: int) -> SkinMesh | None:
        """The mesh of `skeleton`'s body shape at detail `level`, made once per shape
        (None: it cannot be meshed)."""
        layout = skeleton.layout
        key = (
            level,
            layout.mantle_radius,
            layout.mantle_height,
            *((t.angle, t.lengths.tobytes(), t.radii.tobytes()) for t in layout.tentacles),
        )
        if key not in self._meshes:
            try:
                self._meshes[key] = creature_mesh(skeleton, DETAILS[level])
            except MeshError:
                self._meshes[key] = None
        return self._meshes[key]

    def choose_detail(self, pos: np.ndarray, eye: np.ndarray, per_metre: float) -> None:
        """Each creature's level for this frame: coarse when its reach spans fewer than
        `COARSE_PIXELS` pixels seen from `eye` (`per_metre`: a pixel's size 1 m away),
        tiny under `TINY_PIXELS`."""
        if not len(self.mantle_rows):
            return
        distance = np.linalg.norm(pos[self.mantle_rows] - eye, axis=1)
        pixels = 2.0 * self.reach / np.maximum(distance * per_metre, 1e-9)
        self.level = (pixels < COARSE_PIXELS).astype(np.int64) + (pixels < TINY_PIXELS)

    def palette(self, pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
        """(J, 3, 4) float32 world * bind^-1 of every joint for body poses `pos`, `quat`."""
        rotation = quat_matrix(quat[self.rows])
        origin = pos[self.rows] + rotation[:, :, 0] * self.offset[:, None]
        out = rotation @ self.inverse_bind[:, :3, :]
        out[:, :, 3] += origin
        return out.astype(np.float32)

    def update(self, pos: np.ndarray, quat: np.ndarray) -> None:
        """Upload this frame's palette (rows of ROW_JOINTS joints, 3 RGBA texels each)."""
        if not len(self.rows):
            return
        joints = len(self.rows)
        height = -(-joints // ROW_JOINTS)
        texels = np.zeros((height * ROW_JOINTS, 3, 4), np.float32)
        texels[:joints] = self.palette(pos, quat)
        gl.glBindTexture(gl.GL_TEXTURE_2D, self.texture)
        gl.glPixelStorei(gl.GL_UNPACK_ALIGNMENT, 4)
        gl.glTexImage2D(
            gl.GL_TEXTURE_2D,
            0,
            gl.GL_RGBA32F,
            3 * ROW_JOINTS,
            height,
            0,
            gl.GL_RGBA,
            gl.GL_FLOAT,
            texels.ctypes.data_as(ctypes.c_void_p),
        )
        # one level, no filtering: complete (set here, with the texture surely bound)
        for parameter in (gl.GL_TEXTURE_MIN_FILTER, gl.GL_TEXTURE_MAG_FILTER):
            gl.glTexParameteri(gl.GL_TEXTURE_2D, parameter, gl.GL_NEAREST)
        gl.glTexParameteri(gl.GL_TEXTURE_2D, gl.GL_TEXTURE_MAX_LEVEL, 0)
        gl.glBindTexture(gl.GL_TEXTURE_2D, 0)

    @property
    def triangles(self) -> int:
        """Triangles drawn at the levels chosen for this frame."""
        creatures = np.arange(len(self.level))
        return int(self.counts[self.level, creatures].sum()) // 3

    def draw(self) -> int:
        """One multi-draw of every skinned creature, each at its level; returns 1."""
        n = len(self.level)
        if not n:
            return 0
        creatures = np.arange(n)
        counts = np.ascontiguousarray(self.counts[self.level, creatures], np.int32)
        starts = np.ascontiguousarray(self.first[self.level, creatures], np.uintp)
        gl.glActiveTexture(gl.GL_TEXTURE0)
        gl.glBindTexture(gl.GL_TEXTURE_2D, self.texture)
        gl.glBindVertexArray(self.vao)
        gl.glMultiDrawElements(
            gl.GL_TRIANGLES,
            counts.ctypes.data_as(ctypes.POINTER(gl.GLsizei)),
            gl.GL_UNSIGNED_INT,
            starts.ctypes.data_as(ctypes.POINTER(ctypes.c_void_p)),
            n,
        )
        gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
        return 1
