"""What is drawn before the creatures: the ground (the plane's metre grid, or the
ground's meshes: the terrain, the ground beyond it out to the horizon and the
obstacles, lit: `Ground.meshes`), fogged with distance in the sky's horizon colour so
the ground joins the sky, then the sky's gradient where no ground was drawn.

The sky comes last, at the far plane under a depth test, so only its visible pixels are
shaded: drawn first it shaded all 1280 x 720 and the ground then covered most of them
(7.5 of a 53 ms frame in software GL for a crowd framed from above; the pictures are
the same to the bit).

While the camera stands still the picture of the ground and the sky does not change:
`draw_kept` keeps the second still frame's colour and depth in a picture of its own
(`kept`) and from the third on copies them into the target instead of drawing them (a
copy of 1280 x 720 colour and depth against the ground's 73,728 terrain triangles and
half a million shaded pixels at 256 creatures on rocky ground). A camera that moves
draws the ground every frame and keeps nothing.

Reads the world's `Ground` (`ground_of`), the camera's view, the light; writes only the
framebuffer bound by the caller (`Renderer.draw`) and its own GL objects. The ground's
meshes are made again only when the world has another `Ground` (a new world, a terrain
edit). `set_fog` puts the same fog on the renderer's other programs; `use_lit` readies a lit
surface's program (the terrain's, the creatures').
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pyglet import gl
from pyglet.graphics.shader import ShaderProgram

from ecs_tentacles.ground import Ground
from ecs_tentacles.render import shaders
from ecs_tentacles.render.gpu import (
    INSTANCE_FLOATS,
    InstancedMesh,
    Quad,
    ScreenTriangle,
    Target,
    program,
    set_matrix,
)
from ecs_tentacles.render.horizon import HORIZON, REACH, ZENITH
from ecs_tentacles.render.meshes import Mesh


@dataclass(frozen=True, eq=False)
class Sight:
    """What the ground is drawn for: the camera's `view_projection` and `eye`, the
    `light`, the `fog` (`render.horizon.fog_range`) and whether the metre `grid` shows
    (False: the clean view)."""

    view_projection: np.ndarray
    eye: tuple[float, ...]
    light: np.ndarray
    fog: tuple[float, float]
    grid: bool = True

    def key(self) -> tuple[object, ...]:
        """Equal for two sights that draw the same picture."""
        return (
            np.asarray(self.view_projection, np.float64).tobytes(),
            self.eye,
            tuple(np.asarray(self.light, np.float64)),
            self.fog,
            self.grid,
        )


def set_fog(prog: ShaderProgram, fog: tuple[float, float]) -> None:
    """The distance fog's uniforms (`render.horizon.fog_range`) on a program that fogs."""
    prog["u_fog_colour"] = HORIZON
    prog["u_fog_start"], prog["u_fog_end"] = fog


def use_lit(
    prog: ShaderProgram,
    view_projection: np.ndarray,
    light: np.ndarray,
    eye: tuple[float, ...],
    fog: tuple[float, float],
) -> None:
    """Make `prog`, a lit and fogged surface's program, current with this frame's
    view-projection, light direction, eye and fog."""
    prog.use()
    set_matrix(prog, "u_view_projection", view_projection)
    prog["u_light"] = tuple(light.astype(np.float32))
    prog["u_eye"] = eye
    set_fog(prog, fog)


class Scenery:
    """The sky and the ground's GPU objects, and their draws."""

    def __init__(self) -> None:
        self.sky_program = program(shaders.SKY_VERTEX, shaders.SKY_FRAGMENT)
        self.sky = ScreenTriangle()
        self.ground_program = program(shaders.GROUND_VERTEX, shaders.GROUND_FRAGMENT)
        self.plane = Quad(REACH)  # the plane, out to where the fog has hidden it
        self.terrain_program = program(shaders.INSTANCED_VERTEX, shaders.TERRAIN_FRAGMENT)
        self.ground_meshes: list[InstancedMesh] = []  # the terrain and obstacles, if any
        self.ground_drawn: object = None  # the Ground they were made from
        # `draw_kept`: the ground and sky of a still camera, what they were drawn for
        # (and the draw calls they took), and what the frame before was drawn for
        self.kept: Target | None = None
        self.kept_for: tuple[object, ...] | None = None
        self.kept_calls = 0
        self.last_for: tuple[object, ...] | None = None
        self._kept_ground: object = None  # holds the ground whose id is in `kept_for`

    def build(self, ground: Ground) -> None:
        """The ground's meshes (terrain, the ground beyond it, obstacles) as one-instance
        meshes; nothing to do when they were made from this `ground` already."""
        if ground is self.ground_drawn:
            return
        self.ground_drawn = ground
        for old in self.ground_meshes:
            old.delete()
        self.ground_meshes = []
        for part in ground.meshes():  # the terrain's: surface, beyond it, obstacles
            mesh, colour, grid = part.mesh, part.rgb, part.grid
            template = Mesh(
                mesh.vertices.astype(np.float32),
                mesh.normals.astype(np.float32),
                np.zeros(len(mesh.vertices), np.float32),
                mesh.triangles.astype(np.uint32).ravel(),
            )
            drawn = InstancedMesh(template)
            instance = np.zeros((1, INSTANCE_FLOATS), np.float32)
            instance[0, 3] = 1.0  # identity quaternion (w first)
            instance[0, 7:10] = 1.0  # unit scale
            instance[0, 11:15] = (*colour, grid)  # alpha: how much of the metre grid shows
            drawn.update(instance)
            self.ground_meshes.append(drawn)

    def draw(self, ground: Ground, sight: Sight) -> int:
        """The ground as `ground` is now (with its metre grid unless `sight.grid` is
        False: the clean view), then the sky; returns the draw calls. The caller has the
        depth test on and the depth buffer cleared."""
        view_projection, eye, fog, grid = sight.view_projection, sight.eye, sight.fog, sight.grid
        calls = 0
        self.build(ground)  # nothing to do unless the terrain was edited
        if ground.extent is None:  # the plane's grid
            self.ground_program.use()
            set_matrix(self.ground_program, "u_view_projection", view_projection)
            self.ground_program["u_eye"] = eye
            self.ground_program["u_grid"] = float(grid)
            set_fog(self.ground_program, fog)
            gl.glDisable(gl.GL_CULL_FACE)
            calls += self.plane.draw()
            gl.glEnable(gl.GL_CULL_FACE)
        if self.ground_meshes:  # terrain, beyond it, obstacles: lit, three draws at most
            use_lit(self.terrain_program, view_projection, sight.light, eye, fog)
            self.terrain_program["u_grid"] = float(grid)
            for mesh in self.ground_meshes:
                calls += mesh.draw()
        return calls + self.draw_sky(view_projection)

    def draw_kept(self, target: Target, ground: Ground, sight: Sight) -> int:
        """`draw` into `target` (bound, with the scissor the caller wants), or a copy of
        the same picture kept from an earlier frame drawn for the same view; returns the
        draw calls the drawing takes (the same either way)."""
        box = _scissor()
        drawn_for = (*sight.key(), id(ground), target.width, target.height, box)
        if drawn_for == self.kept_for and self.kept is not None:
            _copy(self.kept, target)
            return self.kept_calls
        calls = self.draw(ground, sight)
        if drawn_for == self.last_for and can_keep():  # still since the frame before
            if self.kept is None or (self.kept.width, self.kept.height) != (
                target.width,
                target.height,
            ):
                self.kept = Target(target.width, target.height)
            _copy(target, self.kept)
            target.bind()  # (a new Target binds itself)
            self.kept_for, self.kept_calls, self._kept_ground = drawn_for, calls, ground
        self.last_for = drawn_for
        return calls

    def draw_sky(self, view_projection: np.ndarray) -> int:
        """The sky's gradient at the far plane, on the pixels nothing nearer covers (the
        depth test passes only where the depth is still the cleared 1.0; none written)."""
        self.sky_program.use()
        set_matrix(self.sky_program, "u_inverse_view_projection", np.linalg.inv(view_projection))
        self.sky_program["u_horizon"] = HORIZON
        self.sky_program["u_zenith"] = ZENITH
        gl.glDepthFunc(gl.GL_LEQUAL)
        gl.glDepthMask(gl.GL_FALSE)
        calls = self.sky.draw()
        gl.glDepthMask(gl.GL_TRUE)
        gl.glDepthFunc(gl.GL_LESS)
        return calls


def _scissor() -> tuple[int, ...]:
    """The scissor box when the scissor test is on (what of the target is drawn), else ()."""
    if not gl.glIsEnabled(gl.GL_SCISSOR_TEST):
        return ()
    box = (gl.GLint * 4)()
    gl.glGetIntegerv(gl.GL_SCISSOR_BOX, box)
    return tuple(box)


def can_keep() -> bool:
    """The context copies images as they are (OpenGL 4.3's glCopyImageSubData): a
    blit's depth may come back a unit off in its last place, and a body touching the
    ground would then flicker where they meet."""
    return bool(gl.gl_info.have_version(4, 3))


def _copy(source: Target, destination: Target) -> None:
    """Colour and depth of `source` into `destination` (the same size), bit for bit."""
    for a, b in ((source.colour, destination.colour), (source.depth, destination.depth)):
        gl.glCopyImageSubData(
            a, gl.GL_RENDERBUFFER, 0, 0, 0, 0,
            b, gl.GL_RENDERBUFFER, 0, 0, 0, 0,
            source.width, source.height, 1,
        )  # fmt: skip
