"""The frame's blended GL passes, each setting the state it needs and leaving it as it
found it: the blob shadows (after the ground, before the lit meshes) and the line
ribbons (after them), neither writing depth.

Reads the meshes and programs the renderer made and this frame's view; writes only the
framebuffer bound by the caller (`Renderer.draw`). Each pass returns its draw calls.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pyglet import gl

from ecs_tentacles.render.gpu import InstancedMesh, SegmentRibbons, set_matrix


def shadow_pass(prog: Any, shadows: InstancedMesh, view_projection: np.ndarray) -> int:
    """The blob shadows: blended over the ground, never hiding what is drawn after."""
    prog.use()
    set_matrix(prog, "u_view_projection", view_projection)
    gl.glEnable(gl.GL_BLEND)
    gl.glBlendFunc(gl.GL_SRC_ALPHA, gl.GL_ONE_MINUS_SRC_ALPHA)
    gl.glDepthMask(gl.GL_FALSE)
    gl.glDisable(gl.GL_CULL_FACE)
    calls = shadows.draw()
    gl.glEnable(gl.GL_CULL_FACE)
    gl.glDepthMask(gl.GL_TRUE)
    gl.glDisable(gl.GL_BLEND)
    return calls


def ribbon_pass(
    prog: Any,
    lines: SegmentRibbons,
    view_projection: np.ndarray,
    eye: tuple[float, ...],
    per_metre: float,
) -> int:
    """The ribbons: over what they lie on (pulled toward the eye), the bright cores over
    their dark edges (no depth written between them)."""
    prog.use()
    set_matrix(prog, "u_view_projection", view_projection)
    prog["u_eye"] = eye
    prog["u_per_metre"] = float(per_metre)
    gl.glEnable(gl.GL_BLEND)
    gl.glBlendFunc(gl.GL_SRC_ALPHA, gl.GL_ONE_MINUS_SRC_ALPHA)
    gl.glDisable(gl.GL_CULL_FACE)
    gl.glDepthMask(gl.GL_FALSE)
    gl.glEnable(gl.GL_POLYGON_OFFSET_FILL)
    gl.glPolygonOffset(-2.0, -8.0)
    calls = lines.draw()
    gl.glDisable(gl.GL_POLYGON_OFFSET_FILL)
    gl.glDepthMask(gl.GL_TRUE)
    gl.glEnable(gl.GL_CULL_FACE)
    gl.glDisable(gl.GL_BLEND)
    return calls
