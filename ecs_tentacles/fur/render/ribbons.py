"""Hair strands drawn as lit, camera-facing ribbons: one indexed draw per kind.

A kind (guides, or child hairs) is n polylines of p points. Each point becomes two
vertices (left, right) carrying its position, the strand's tangent there, the root
width, the position along the strand (for the taper and the root shading) and the
strand's colour; the vertex shader turns them across the view, the fragment shader
lights them (Kajiya-Kay, `RIBBON_FRAGMENT`). The triangle indices depend only
on (n, p) and are rebuilt when those change; vertices are one numpy pass a frame.
"""

from __future__ import annotations

import numpy as np
from pyglet import gl

from ecs_tentacles.fur.hooks import GuideCurves
from ecs_tentacles.render.gpu import FLOAT, _attribute, _buffer, _upload, _vertex_array

VERTEX_FLOATS = 3 + 3 + 3 + 3  # position, tangent, (side, width, along), colour

# Hair strands as camera-facing ribbons: each polyline point comes twice (side -1, +1)
# and is pushed sideways, across the strand and the view, by half its tapered width.
RIBBON_VERTEX = """
#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_tangent;
layout(location = 2) in vec3 a_strand;    // side (-1, 1), width at the root (m), along (0..1)
layout(location = 3) in vec3 a_colour;
uniform mat4 u_view_projection;
uniform vec3 u_eye;
uniform float u_min_width;                // metres: never thinner than about a pixel
out vec3 v_tangent;
out vec3 v_world;
out vec3 v_colour;
out float v_along;
void main() {
    vec3 t = normalize(a_tangent);
    vec3 view = normalize(u_eye - a_position);
    vec3 across = cross(t, view);
    float len = length(across);
    across = len > 1e-6 ? across / len : vec3(0.0, 0.0, 1.0);
    float width = max(a_strand.y * (1.0 - 0.85 * a_strand.z), u_min_width);
    vec3 world = a_position + across * (0.5 * width * a_strand.x);
    v_tangent = t;
    v_world = world;
    v_colour = a_colour;
    v_along = a_strand.z;
    gl_Position = u_view_projection * vec4(world, 1.0);
}
"""

# Kajiya-Kay: diffuse from the sine of the angle between strand and light, a specular
# lobe from the strand and the half vector, shifted toward the tip; roots darker.
RIBBON_FRAGMENT = """
#version 330 core
in vec3 v_tangent;
in vec3 v_world;
in vec3 v_colour;
in float v_along;
uniform vec3 u_light;
uniform vec3 u_eye;
out vec4 f_colour;
void main() {
    vec3 t = normalize(v_tangent);
    vec3 view = normalize(u_eye - v_world);
    vec3 h = normalize(u_light + view);
    float tl = dot(t, u_light);
    float th = dot(t, h);
    float diffuse = sqrt(max(1.0 - tl * tl, 0.0));
    float specular = pow(sqrt(max(1.0 - th * th, 0.0)), 48.0);
    float occlusion = 0.6 + 0.4 * v_along;      // the undercoat is in shadow
    vec3 colour = v_colour * (0.35 + 0.75 * diffuse) * occlusion
        + vec3(0.30, 0.28, 0.25) * specular * (0.3 + 0.7 * v_along);
    f_colour = vec4(colour, 1.0);
}
"""


def strip_indices(strands: int, points: int) -> np.ndarray:
    """Triangles (two per segment) of `strands` ribbons of `points` points, uint32."""
    segment = np.arange(points - 1, dtype=np.uint32) * 2
    quad = np.stack([segment, segment + 1, segment + 2, segment + 1, segment + 3, segment + 2], 1)
    first = np.arange(strands, dtype=np.uint32)[:, None, None] * (2 * points)
    return np.ascontiguousarray((first + quad[None]).reshape(-1))


def ribbon_vertices(curves: GuideCurves) -> np.ndarray:
    """Vertices (n * p * 2, 12) float32 of the ribbons of `curves`."""
    points = curves.points
    n, p = points.shape[:2]
    tangent = np.empty_like(points)
    tangent[:, 1:-1] = points[:, 2:] - points[:, :-2]
    tangent[:, 0] = points[:, 1] - points[:, 0]
    tangent[:, -1] = points[:, -1] - points[:, -2]
    out = np.empty((n, p, 2, VERTEX_FLOATS), np.float32)
    out[..., 0:3] = points[:, :, None]
    out[..., 3:6] = tangent[:, :, None]
    out[..., 6] = (-1.0, 1.0)
    out[..., 7] = curves.width[:, None, None]
    out[..., 8] = np.linspace(0.0, 1.0, p, dtype=np.float32)[None, :, None]
    out[..., 9:12] = curves.colour[:, None, None, :3]
    return out.reshape(-1, VERTEX_FLOATS)


class Ribbons:
    """One kind of strands on the GPU: vertex and index buffers, drawn in one call."""

    def __init__(self) -> None:
        self.vao = _vertex_array()
        gl.glBindVertexArray(self.vao)
        self.vertices = _buffer()
        self.vertex_capacity = [0]
        _upload(
            gl.GL_ARRAY_BUFFER,
            self.vertices,
            np.zeros((2, VERTEX_FLOATS), np.float32),
            self.vertex_capacity,
        )
        stride = VERTEX_FLOATS * FLOAT
        for location in range(4):
            _attribute(location, 3, stride, 3 * location)
        self.indices = _buffer()
        self.index_capacity = [0]
        self.shape = (0, 0)
        self.count = 0
        gl.glBindVertexArray(0)

    def update(self, curves: GuideCurves) -> None:
        """Upload this frame's strands (their count and point count may change)."""
        n, p = curves.points.shape[:2]
        if n == 0 or p < 2:
            self.count = 0
            return
        gl.glBindVertexArray(self.vao)
        if (n, p) != self.shape:
            indices = strip_indices(n, p)
            _upload(gl.GL_ELEMENT_ARRAY_BUFFER, self.indices, indices, self.index_capacity)
            self.shape = (n, p)
        _upload(gl.GL_ARRAY_BUFFER, self.vertices, ribbon_vertices(curves), self.vertex_capacity)
        gl.glBindVertexArray(0)
        self.count = n * (p - 1) * 6

    def draw(self) -> int:
        """Draw the strands (nothing, and no call, when there are none)."""
        if not self.count:
            return 0
        gl.glBindVertexArray(self.vao)
        gl.glDrawElements(gl.GL_TRIANGLES, self.count, gl.GL_UNSIGNED_INT, None)
        return 1
