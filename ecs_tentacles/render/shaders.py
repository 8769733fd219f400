"""GLSL sources (OpenGL 3.3 core)."""

INSTANCED_VERTEX = """
#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_side;
layout(location = 3) in vec3 i_position;
layout(location = 4) in vec4 i_quat;      // w, x, y, z
layout(location = 5) in vec4 i_scale;     // xyz scale, w: extend along x per side
layout(location = 6) in vec4 i_colour;
uniform mat4 u_view_projection;
out vec3 v_normal;
out vec4 v_colour;
out vec3 v_world;

vec3 rotate(vec4 q, vec3 v) {
    vec3 t = 2.0 * cross(q.yzw, v);
    return v + q.x * t + cross(q.yzw, t);
}

void main() {
    vec3 local = a_position * i_scale.xyz + vec3(a_side * i_scale.w, 0.0, 0.0);
    vec3 world = i_position + rotate(i_quat, local);
    v_normal = rotate(i_quat, normalize(a_normal / i_scale.xyz));
    v_colour = i_colour;
    v_world = world;
    gl_Position = u_view_projection * vec4(world, 1.0);
}
"""

# what a lit surface's fragment shader takes (the instanced vertex shader's outputs)
_LIT_HEAD = """
#version 330 core
in vec3 v_normal;
in vec4 v_colour;
in vec3 v_world;
uniform vec3 u_light;
uniform vec3 u_eye;
out vec4 f_colour;
"""

# distance fog: what is far off fades into the sky's colour at the horizon; it starts
# beyond the point looked at (`u_fog_start`) and is all but complete at `u_fog_end` (the
# renderer sets both from the camera's distance), so the ground meets the sky
_FOG_FUNCTION = """uniform vec3 u_fog_colour;
uniform float u_fog_start;
uniform float u_fog_end;
float fog_amount(vec3 world) {
    float t = max(length(world - u_eye) - u_fog_start, 0.0) / (u_fog_end - u_fog_start);
    return 1.0 - exp(-3.0 * t);  // a haze that thickens, 95 % at u_fog_end
}
vec3 fogged(vec3 colour, vec3 world) {
    return mix(colour, u_fog_colour, fog_amount(world));
}
"""

LIT_FRAGMENT = (
    _LIT_HEAD
    + _FOG_FUNCTION
    + """void main() {
    vec3 n = normalize(v_normal);
    float diffuse = max(dot(n, u_light), 0.0);
    float sky = 0.5 + 0.5 * n.z;                       // hemisphere ambient
    vec3 view = normalize(u_eye - v_world);
    float rim = pow(1.0 - max(dot(n, view), 0.0), 3.0) * 0.25;
    vec3 half_vector = normalize(u_light + view);
    float specular = pow(max(dot(n, half_vector), 0.0), 24.0) * 0.25;
    vec3 colour = v_colour.rgb * (0.32 + 0.25 * sky + 0.6 * diffuse) + rim + specular;
    f_colour = vec4(fogged(colour, v_world), v_colour.a);
}
"""
)

GROUND_VERTEX = """
#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
out vec3 v_world;
void main() {
    v_world = a_position;
    gl_Position = u_view_projection * vec4(a_position, 1.0);
}
"""

# lines on the ground every `spacing` metres, `width` pixels wide (1 on a line, 0 off it)
_GRID = """float grid(vec2 p, float spacing, float width) {
    vec2 g = abs(fract(p / spacing - 0.5) - 0.5) / fwidth(p / spacing);
    return 1.0 - min(min(g.x, g.y) / width, 1.0);
}
"""
# the ground fades into the sky's colour at the horizon with distance
_FOG = """    f_colour = vec4(fogged(colour, v_world), 1.0);
"""

GROUND_FRAGMENT = (
    """
#version 330 core
in vec3 v_world;
uniform vec3 u_eye;
uniform float u_grid;  // 1: the metre grid drawn, 0: none (the clean view)
out vec4 f_colour;
// @grid
// @fog_function
void main() {
    // sand, lit as the terrain is from straight above, with a faint quarter-metre and
    // a clearer metre grid for scale (gone in the haze, where it would only shimmer);
    // low-frequency mottling so it reads as ground
    vec2 p = v_world.xy;
    float mottle = 0.04 * sin(p.x * 1.7 + sin(p.y * 1.3)) * sin(p.y * 2.1 + sin(p.x * 0.9));
    vec3 base = vec3(0.66, 0.59, 0.47) * (1.0 + mottle);
    float clear = (1.0 - fog_amount(v_world)) * u_grid;
    float fine = grid(p, 0.25, 1.0) * 0.06 * clear;
    float coarse = grid(p, 1.0, 1.5) * 0.18 * clear;
    vec3 colour = mix(base, base * 0.62, fine + coarse);
    // @fog
}
""".replace("// @grid\n", _GRID)
    .replace("// @fog_function\n", _FOG_FUNCTION)
    .replace("    // @fog\n", _FOG)
)

TERRAIN_FRAGMENT = (
    _LIT_HEAD
    + _FOG_FUNCTION
    + """// @grid
uniform float u_grid;  // 1: the metre grid drawn, 0: none (the clean view)
void main() {
    vec3 n = normalize(gl_FrontFacing ? v_normal : -v_normal);
    float diffuse = max(dot(n, u_light), 0.0);
    float sky = 0.5 + 0.5 * n.z;
    vec3 colour = v_colour.rgb * (0.30 + 0.25 * sky + 0.62 * diffuse);
    // a faint metre grid on the ground (scale at a glance), as on the plane
    float clear = (1.0 - fog_amount(v_world)) * u_grid;
    colour = mix(colour, colour * 0.6, grid(v_world.xy, 1.0, 1.5) * 0.35 * v_colour.a * clear);
    // @fog
}
""".replace("// @grid\n", _GRID).replace("    // @fog\n", _FOG)
)

# the sky behind everything: a full-screen triangle whose pixels look along their view
# ray, hazy at the horizon (the fog's colour) and bluer toward the zenith
SKY_VERTEX = """
#version 330 core
layout(location = 0) in vec2 a_position;
out vec2 v_ndc;
void main() {
    v_ndc = a_position;
    gl_Position = vec4(a_position, 1.0, 1.0);
}
"""

SKY_FRAGMENT = """
#version 330 core
in vec2 v_ndc;
uniform mat4 u_inverse_view_projection;
uniform vec3 u_horizon;
uniform vec3 u_zenith;
out vec4 f_colour;
void main() {
    vec4 near = u_inverse_view_projection * vec4(v_ndc, -1.0, 1.0);
    vec4 far = u_inverse_view_projection * vec4(v_ndc, 1.0, 1.0);
    vec3 direction = normalize(far.xyz / far.w - near.xyz / near.w);
    float up = clamp(direction.z, 0.0, 1.0);
    f_colour = vec4(mix(u_horizon, u_zenith, pow(up, 0.55)), 1.0);
}
"""

BLOB_VERTEX = """
#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 3) in vec3 i_position;
layout(location = 5) in vec4 i_scale;
layout(location = 6) in vec4 i_colour;
uniform mat4 u_view_projection;
out vec2 v_local;
out vec4 v_colour;
void main() {
    v_local = a_position.xy;
    v_colour = i_colour;
    vec3 world = i_position + vec3(a_position.xy * i_scale.xy, 0.0);
    gl_Position = u_view_projection * vec4(world, 1.0);
}
"""

BLOB_FRAGMENT = """
#version 330 core
in vec2 v_local;
in vec4 v_colour;
out vec4 f_colour;
void main() {
    float r = length(v_local);
    float alpha = v_colour.a * (1.0 - smoothstep(0.2, 1.0, r));
    if (alpha <= 0.003) discard;
    f_colour = vec4(v_colour.rgb, alpha);
}
"""

LINE_FRAGMENT = """
#version 330 core
in vec4 v_colour;
out vec4 f_colour;
void main() { f_colour = v_colour; }
"""

SKINNED_VERTEX = """
#version 330 core
layout(location = 0) in vec3 a_position;   // bind pose, the creature's mantle frame
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
layout(location = 3) in vec2 a_joints;     // two palette indices
layout(location = 4) in float a_weight;    // of the second joint
uniform mat4 u_view_projection;
uniform sampler2D u_palette;  // 3 texels (rows of world * bind^-1) per joint, 512 joints a row
out vec3 v_normal;
out vec4 v_colour;
out vec3 v_world;

mat4 joint(float index) {
    int j = int(index + 0.5);
    ivec2 at = ivec2(3 * (j % 512), j / 512);
    return transpose(mat4(texelFetch(u_palette, at, 0), texelFetch(u_palette, at + ivec2(1, 0), 0),
                          texelFetch(u_palette, at + ivec2(2, 0), 0), vec4(0.0, 0.0, 0.0, 1.0)));
}

void main() {
    mat4 m = (1.0 - a_weight) * joint(a_joints.x) + a_weight * joint(a_joints.y);
    vec4 world = m * vec4(a_position, 1.0);
    v_normal = mat3(m) * a_normal;
    v_colour = vec4(a_colour, 1.0);
    v_world = world.xyz;
    gl_Position = u_view_projection * world;
}
"""
