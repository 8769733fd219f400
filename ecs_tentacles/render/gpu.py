"""Thin OpenGL helpers: programs, instanced meshes, line lists, an off-screen target.

Buffers are filled from numpy arrays in one call each; a mesh kind draws all its
instances with one instanced call, however many creatures there are.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np
from pyglet import gl
from pyglet.graphics.shader import Shader, ShaderProgram

from ecs_tentacles.render.meshes import Mesh

FLOAT = 4
INSTANCE_FLOATS = 3 + 4 + 4 + 4  # position, quat, scale + extend, colour


def program(vertex: str, fragment: str) -> ShaderProgram:
    return ShaderProgram(Shader(vertex, "vertex"), Shader(fragment, "fragment"))


def set_matrix(prog: ShaderProgram, name: str, matrix: np.ndarray) -> None:
    prog[name] = tuple(np.asarray(matrix, dtype=np.float32).T.reshape(-1))


def _buffer() -> int:
    handle = gl.GLuint()
    gl.glGenBuffers(1, ctypes.byref(handle))
    return handle.value


def _vertex_array() -> int:
    handle = gl.GLuint()
    gl.glGenVertexArrays(1, ctypes.byref(handle))
    return handle.value


def _upload(target: int, buffer: int, data: np.ndarray, capacity: list[int]) -> None:
    """Write `data` into `buffer`, growing it (orphaning) when it is too small."""
    data = np.ascontiguousarray(data)
    gl.glBindBuffer(target, buffer)
    if data.nbytes > capacity[0]:
        capacity[0] = max(data.nbytes, 2 * capacity[0])
        gl.glBufferData(target, capacity[0], None, gl.GL_DYNAMIC_DRAW)
    if data.nbytes:
        gl.glBufferSubData(target, 0, data.nbytes, data.ctypes.data_as(ctypes.c_void_p))


def _attribute(location: int, size: int, stride: int, offset: int, divisor: int = 0) -> None:
    gl.glEnableVertexAttribArray(location)
    gl.glVertexAttribPointer(
        location, size, gl.GL_FLOAT, gl.GL_FALSE, stride, ctypes.c_void_p(offset * FLOAT)
    )
    if divisor:
        gl.glVertexAttribDivisor(location, divisor)


class InstancedMesh:
    """One mesh template, drawn once per row of an instance array (one draw call)."""

    def __init__(self, mesh: Mesh):
        self.mesh = mesh
        self.vao = _vertex_array()
        gl.glBindVertexArray(self.vao)
        self.vertices = _buffer()
        _upload(gl.GL_ARRAY_BUFFER, self.vertices, mesh.vertex_data(), [0])
        stride = 7 * FLOAT
        _attribute(0, 3, stride, 0)
        _attribute(1, 3, stride, 3)
        _attribute(2, 1, stride, 6)
        self.indices = _buffer()
        _upload(gl.GL_ELEMENT_ARRAY_BUFFER, self.indices, mesh.indices, [0])
        self.instances = _buffer()
        self.capacity = [0]
        _upload(
            gl.GL_ARRAY_BUFFER,
            self.instances,
            np.zeros((1, INSTANCE_FLOATS), np.float32),
            self.capacity,
        )
        stride = INSTANCE_FLOATS * FLOAT
        for location, (size, offset) in enumerate(((3, 0), (4, 3), (4, 7), (4, 11)), start=3):
            _attribute(location, size, stride, offset, divisor=1)
        gl.glBindVertexArray(0)
        self.count = 0

    def update(self, instances: np.ndarray) -> None:
        """Replace the instances: float32 (n, 15) rows of position, quat, scale, colour."""
        self.count = len(instances)
        _upload(
            gl.GL_ARRAY_BUFFER,
            self.instances,
            instances.astype(np.float32, copy=False),
            self.capacity,
        )

    def delete(self) -> None:
        """Free its GL buffers and vertex array (a mesh that is replaced: an edited terrain)."""
        buffers = (gl.GLuint * 3)(self.vertices, self.indices, self.instances)
        gl.glDeleteBuffers(3, buffers)
        gl.glDeleteVertexArrays(1, ctypes.byref(gl.GLuint(self.vao)))

    def draw(self) -> int:
        """Draw every instance (zero instances still make the one call); returns 1."""
        gl.glBindVertexArray(self.vao)
        gl.glDrawElementsInstanced(
            gl.GL_TRIANGLES, len(self.mesh.indices), gl.GL_UNSIGNED_INT, None, self.count
        )
        return 1


class SegmentRibbons:
    """Line segments drawn as ribbons a vertex shader makes (`render.outlines`): one
    instance a segment, six corners each, one instanced call."""

    def __init__(self, instance_floats: int, layout: tuple[tuple[int, int], ...]) -> None:
        self.floats = instance_floats
        self.vao = _vertex_array()
        gl.glBindVertexArray(self.vao)
        self.buffer = _buffer()
        self.capacity = [0]
        empty = np.zeros((1, instance_floats), np.float32)
        _upload(gl.GL_ARRAY_BUFFER, self.buffer, empty, self.capacity)
        for location, (size, offset) in enumerate(layout):
            _attribute(location, size, instance_floats * FLOAT, offset, divisor=1)
        gl.glBindVertexArray(0)
        self.count = 0

    def update(self, instances: np.ndarray) -> None:
        """float32 (n, instance_floats): one row a segment."""
        self.count = len(instances)
        _upload(
            gl.GL_ARRAY_BUFFER, self.buffer, instances.astype(np.float32, copy=False), self.capacity
        )

    def draw(self) -> int:
        gl.glBindVertexArray(self.vao)
        gl.glDrawArraysInstanced(gl.GL_TRIANGLES, 0, 6, self.count)
        return 1


class Quad:
    """A flat square on z = 0 (the ground)."""

    def __init__(self, half_size: float):
        s = half_size
        data = np.array(
            [[-s, -s, 0], [s, -s, 0], [s, s, 0], [-s, -s, 0], [s, s, 0], [-s, s, 0]], np.float32
        )
        self.vao = _vertex_array()
        gl.glBindVertexArray(self.vao)
        self.buffer = _buffer()
        _upload(gl.GL_ARRAY_BUFFER, self.buffer, data, [0])
        _attribute(0, 3, 3 * FLOAT, 0)
        gl.glBindVertexArray(0)

    def draw(self) -> int:
        gl.glBindVertexArray(self.vao)
        gl.glDrawArrays(gl.GL_TRIANGLES, 0, 6)
        return 1


class ScreenTriangle:
    """One triangle that covers the whole picture (normalised device coordinates): the sky."""

    def __init__(self) -> None:
        data = np.array([[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]], np.float32)
        self.vao = _vertex_array()
        gl.glBindVertexArray(self.vao)
        self.buffer = _buffer()
        _upload(gl.GL_ARRAY_BUFFER, self.buffer, data, [0])
        _attribute(0, 2, 2 * FLOAT, 0)
        gl.glBindVertexArray(0)

    def draw(self) -> int:
        gl.glBindVertexArray(self.vao)
        gl.glDrawArrays(gl.GL_TRIANGLES, 0, 3)
        return 1


@dataclass
class Target:
    """An off-screen RGBA8 colour + depth framebuffer of a fixed size."""

    width: int
    height: int

    def __post_init__(self) -> None:
        handle = gl.GLuint()
        gl.glGenFramebuffers(1, ctypes.byref(handle))
        self.framebuffer = handle.value
        gl.glBindFramebuffer(gl.GL_FRAMEBUFFER, self.framebuffer)
        buffers = (gl.GLuint * 2)()
        gl.glGenRenderbuffers(2, buffers)
        self.colour, self.depth = buffers[0], buffers[1]
        for buffer, fmt, attachment in (
            (self.colour, gl.GL_RGBA8, gl.GL_COLOR_ATTACHMENT0),
            (self.depth, gl.GL_DEPTH_COMPONENT24, gl.GL_DEPTH_ATTACHMENT),
        ):
            gl.glBindRenderbuffer(gl.GL_RENDERBUFFER, buffer)
            gl.glRenderbufferStorage(gl.GL_RENDERBUFFER, fmt, self.width, self.height)
            gl.glFramebufferRenderbuffer(gl.GL_FRAMEBUFFER, attachment, gl.GL_RENDERBUFFER, buffer)
        status = gl.glCheckFramebufferStatus(gl.GL_FRAMEBUFFER)
        if status != gl.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError(f"off-screen framebuffer incomplete (status {status:#x})")

    def bind(self) -> None:
        gl.glBindFramebuffer(gl.GL_FRAMEBUFFER, self.framebuffer)
        gl.glViewport(0, 0, self.width, self.height)

    def read(self) -> np.ndarray:
        """The picture as uint8 (height, width, 3), top row first."""
        gl.glBindFramebuffer(gl.GL_READ_FRAMEBUFFER, self.framebuffer)
        pixels = np.empty((self.height, self.width, 4), np.uint8)
        gl.glPixelStorei(gl.GL_PACK_ALIGNMENT, 1)
        gl.glReadPixels(
            0,
            0,
            self.width,
            self.height,
            gl.GL_RGBA,
            gl.GL_UNSIGNED_BYTE,
            pixels.ctypes.data_as(ctypes.c_void_p),
        )
        return pixels[::-1, :, :3].copy()

    def blit_to_window(self, width: int, height: int) -> None:
        """Copy the picture to the window's own framebuffer."""
        gl.glBindFramebuffer(gl.GL_READ_FRAMEBUFFER, self.framebuffer)
        gl.glBindFramebuffer(gl.GL_DRAW_FRAMEBUFFER, 0)
        gl.glBlitFramebuffer(
            0, 0, self.width, self.height, 0, 0, width, height, gl.GL_COLOR_BUFFER_BIT, gl.GL_LINEAR
        )
        gl.glBindFramebuffer(gl.GL_FRAMEBUFFER, 0)
