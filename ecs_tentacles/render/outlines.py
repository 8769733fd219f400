"""Lines that stand out on any ground: every line segment the renderer draws (goal
rings and paths, selection rings, plugins' markers) becomes a flat ribbon facing the
camera, a dark one `OUTLINE_PIXELS` wide under a bright one `LINE_PIXELS` wide in the
line's colour (a dull one lifted toward white). Light sand and grey rock alike then show a dark edge
and a bright core: the ring reads on both (a one-pixel line in a creature's colour
vanished on sand). One instanced draw: a segment is an instance (its two ends, colour
and width in pixels: `ribbon_instances`, the dark edges first, the bright cores after),
turned into its six corners by the vertex shader (`RIBBON_VERTEX`), so a crowd's
12,000 goal-ring segments cost no per-frame numpy (they took 9 ms of CPU a frame at
256 creatures when the corners were made in numpy).
"""

from __future__ import annotations

import numpy as np

LINE_PIXELS = 2.2  # the bright core's width
OUTLINE_PIXELS = 5.0  # the dark edge's width (under the core)
OUTLINE = (0.06, 0.05, 0.05, 0.9)
LIFT = 0.5  # how far a dull core colour goes toward white (a bright one hardly moves)
INSTANCE_FLOATS = 3 + 3 + 4 + 1  # end a, end b, rgba, width (pixels)

# A segment instance's six corners (two triangles: a0 b0 b1, a0 b1 a1), each end pushed
# across the segment and the view by half the width at that end's distance from the eye
# (`u_per_metre`: a pixel's size one metre from the eye).
RIBBON_VERTEX = """
#version 330 core
layout(location = 0) in vec3 i_a;
layout(location = 1) in vec3 i_b;
layout(location = 2) in vec4 i_colour;
layout(location = 3) in float i_width;
uniform mat4 u_view_projection;
uniform vec3 u_eye;
uniform float u_per_metre;
out vec4 v_colour;
const float END[6] = float[6](0.0, 1.0, 1.0, 0.0, 1.0, 0.0);
const float SIDE[6] = float[6](-1.0, -1.0, 1.0, -1.0, 1.0, 1.0);
void main() {
    vec3 along = i_b - i_a;
    vec3 side = cross(along, 0.5 * (i_a + i_b) - u_eye);
    float length_ = length(side);
    side = length_ > 1e-12 ? side / length_ : vec3(0.0);
    vec3 end = END[gl_VertexID] > 0.5 ? i_b : i_a;
    float reach = length(end - u_eye) * u_per_metre / 2.0;
    vec3 world = end + SIDE[gl_VertexID] * side * reach * i_width;
    v_colour = i_colour;
    gl_Position = u_view_projection * vec4(world, 1.0);
}
"""


def ribbon_instances(segments: np.ndarray) -> np.ndarray:
    """Instances (2n, INSTANCE_FLOATS) float32 for segments (2n, 7) (end points, rgba):
    the dark edges first, the bright cores after."""
    ends = segments.reshape(-1, 2, 7)
    n = len(ends)
    out = np.empty((2, n, INSTANCE_FLOATS), np.float32)
    if not n:
        return out.reshape(0, INSTANCE_FLOATS)
    out[:, :, 0:3] = ends[:, 0, :3]
    out[:, :, 3:6] = ends[:, 1, :3]
    core = ends[:, 0, 3:7].astype(np.float64)
    dullness = 1.0 - core[:, :3] @ [0.2126, 0.7152, 0.0722]  # bright colours stay as they are
    core[:, :3] += LIFT * dullness[:, None] * (1.0 - core[:, :3])
    out[0, :, 6:10] = OUTLINE
    out[1, :, 6:10] = core
    out[0, :, 10] = OUTLINE_PIXELS
    out[1, :, 10] = LINE_PIXELS
    return out.reshape(-1, INSTANCE_FLOATS)
