"""Skinned creatures in the sandbox: every creature's mesh in one buffer, one draw call.

The meshes are `ecs_tentacles.skin.mesh` creature meshes (the ones the exporters write),
built once per world in each creature's mantle frame and concatenated; each vertex
names two joints of one palette shared by all creatures. Per frame one numpy pass
turns the body poses into the palette (a 3 x 4 world * bind^-1 matrix per joint) and
one upload puts it in a float texture (512 joints a row); the vertex shader
(`shaders.SKINNED_VERTEX`)
blends the vertex's two joints. However many creatures, that is one draw call.
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
    return base + 0.55 * underside[:, None] * (PALE - base)


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
        self.count = 0
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
        cache = self._meshes
        first_vertex = first_joint = 0
        self.creatures = []
        for entity in entities:
            skeleton = self._skeleton(world, entity)
            layout = skeleton.layout
            key = (
                layout.mantle_radius,
                layout.mantle_height,
                *((t.angle, t.lengths.tobytes(), t.radii.tobytes()) for t in layout.tentacles),
            )
            if key not in cache:
                try:
                    cache[key] = creature_mesh(skeleton, SANDBOX_DETAIL)
                except MeshError:
                    cache[key] = None
            mesh = cache[key]
            if mesh is None:
                continue  # tentacle bases overlap: this one keeps its capsules
            data = np.empty((len(mesh.positions), VERTEX_FLOATS), np.float32)
            data[:, 0:3] = mesh.positions
            data[:, 3:6] = mesh.normals
            data[:, 6:9] = vertex_colours(mesh, skeleton, colours[entity])
            data[:, 9:11] = mesh.joints + first_joint
            data[:, 11] = mesh.weights[:, 1]
            parts.append(data)
            indices.append(mesh.faces.reshape(-1) + first_vertex)
            rows.append(skeleton.bodies)
            offsets.append(skeleton.offset)
            binds.append(skeleton.bind)
            first_vertex += len(mesh.positions)
            first_joint += len(skeleton.names)
            self.creatures.append(entity)
        vertex_data = np.vstack(parts) if parts else np.zeros((0, VERTEX_FLOATS), np.float32)
        index_data = (
            np.concatenate(indices).astype(np.uint32) if indices else np.zeros(0, np.uint32)
        )
        gl.glBindVertexArray(self.vao)
        _upload(gl.GL_ARRAY_BUFFER, self.vertices, vertex_data, self.vertex_capacity)
        _upload(gl.GL_ELEMENT_ARRAY_BUFFER, self.indices, index_data, self.index_capacity)
        gl.glBindVertexArray(0)
        self.count = len(index_data)
        self.rows = np.concatenate(rows) if rows else np.zeros(0, np.int64)
        self.offset = np.concatenate(offsets) if offsets else np.zeros(0)
        self.inverse_bind = np.linalg.inv(np.concatenate(binds)) if binds else np.zeros((0, 4, 4))

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

    def draw(self) -> int:
        """One indexed draw of every skinned creature; returns 1."""
        gl.glActiveTexture(gl.GL_TEXTURE0)
        gl.glBindTexture(gl.GL_TEXTURE_2D, self.texture)
        gl.glBindVertexArray(self.vao)
        gl.glDrawElements(gl.GL_TRIANGLES, self.count, gl.GL_UNSIGNED_INT, None)
        gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
        return 1
