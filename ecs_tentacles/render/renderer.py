"""Draws a World: ground grid, creatures, attached suckers, goals and paths.

Creatures are drawn skinned by default (`view = "skinned"`: one continuous mesh per
creature, skinned on the GPU, all creatures in one draw; `ecs_tentacles.render.skinned`)
or as the physics sees them (`view = "capsules"`: a cylinder per mantle, a capsule per
link). Per frame: one numpy pass fills each mesh kind's instance array from the
Transform store (interpolated between the last two physics frames), one upload per
kind, one draw per kind (capsule links in two levels of detail). Draw calls do not
grow with the number of creatures.
"""

from __future__ import annotations

import colorsys
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pyglet import gl

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.fur.hooks import GuideCurves, child_hairs, guide_curves
from ecs_tentacles.fur.render.markers import marker_lines
from ecs_tentacles.fur.render.ribbons import Ribbons
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.render import shaders
from ecs_tentacles.render.camera import OrbitCamera
from ecs_tentacles.render.gpu import (
    INSTANCE_FLOATS,
    InstancedMesh,
    Lines,
    Quad,
    Target,
    program,
    set_matrix,
)
from ecs_tentacles.render.meshes import CAPSULE_LODS, CYLINDER_LOD, SPHERE_LOD
from ecs_tentacles.render.skinned import SkinnedCreatures
from ecs_tentacles.world import World

SKY = (0.70, 0.76, 0.82)
LIGHT = np.array([0.35, -0.45, 0.82]) / np.linalg.norm([0.35, -0.45, 0.82])
LOD_DISTANCE = 6.0  # metres from the eye beyond which links use the lean mesh
VIEWS = ("skinned", "capsules")
RING_SEGMENTS = 48
_ANGLES = np.linspace(0, 2 * np.pi, RING_SEGMENTS + 1)
CIRCLE = np.stack([np.cos(_ANGLES), np.sin(_ANGLES), np.zeros_like(_ANGLES)], axis=1)


def creature_colours(count: int) -> np.ndarray:
    """Distinct warm colours (count, 3), octopus-like."""
    hues = (0.02 + 0.61803 * np.arange(count)) % 1.0
    return np.array([colorsys.hsv_to_rgb(h, 0.65, 0.85) for h in hues]).reshape(-1, 3)


def _nlerp(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    b = np.where((np.einsum("ij,ij->i", a, b) < 0)[:, None], -b, b)
    q = a + t * (b - a)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


class Renderer:
    """GPU objects and per-frame instance arrays for one world."""

    def __init__(self, world: World, width: int, height: int):
        self.world = world
        self.target = Target(width, height)
        self.camera = OrbitCamera(width, height)
        self.lit = program(shaders.INSTANCED_VERTEX, shaders.LIT_FRAGMENT)
        self.ground_program = program(shaders.GROUND_VERTEX, shaders.GROUND_FRAGMENT)
        self.line_program = program(shaders.LINE_VERTEX, shaders.LINE_FRAGMENT)
        self.skinned_program = program(shaders.SKINNED_VERTEX, shaders.LIT_FRAGMENT)
        self.skinned = SkinnedCreatures()
        self.view = "skinned"
        self.ground = Quad(200.0)
        self.mantles = InstancedMesh(CYLINDER_LOD)
        self.links_near = InstancedMesh(CAPSULE_LODS[0])
        self.links_far = InstancedMesh(CAPSULE_LODS[1])
        self.suckers = InstancedMesh(SPHERE_LOD)
        self.lines = Lines()
        self.ribbon_program = program(shaders.RIBBON_VERTEX, shaders.RIBBON_FRAGMENT)
        self.guide_ribbons = Ribbons()
        self.child_ribbons = Ribbons()
        self.selected: int | None = None  # creature entity
        self.draw_calls = 0
        self.extra_lines: list[Callable[[World], np.ndarray]] = []  # -> (2n, 7) segments
        self.fur_display = FurDisplay()
        self.set_world(world)

    def set_world(self, world: World) -> None:
        """Draw `world` from now on (same GPU objects, new instance tables)."""
        self.world = world
        self.selected = None
        self._goal_version: int | None = None  # goal lines not built yet
        self._build_static()
        self.previous = (world.transforms.pos.copy(), world.transforms.quat.copy())
        self.current = self.previous

    # -- static per-instance data ------------------------------------------------------
    def _build_static(self) -> None:
        world = self.world
        creatures = sorted(world.query(Creature, Transform))
        colours = creature_colours(len(creatures))
        self.creature_entities = [e for e, _ in creatures]
        self.creature_colour = {e: colours[i] for i, e in enumerate(self.creature_entities)}
        mantle = np.zeros((len(creatures), INSTANCE_FLOATS), np.float32)
        self.mantle_rows = np.array([t.row for _, (_, t) in creatures], dtype=np.int64)
        for i, (_, (creature, _)) in enumerate(creatures):
            r, h = creature.mantle_radius, creature.mantle_height
            mantle[i, 7:11] = (r, r, h / 2, 0.0)
            mantle[i, 11:15] = (*colours[i], 1.0)
        self.mantle_instances = mantle
        link_rows, link_static, link_creature = [], [], []
        for i, entity in enumerate(self.creature_entities):
            creature = world.component(entity, Creature)
            for tentacle_entity in creature.tentacles:
                tentacle = world.component(tentacle_entity, Tentacle)
                n = len(tentacle.links)
                for link_entity in tentacle.links:
                    link = world.component(link_entity, Link)
                    shade = 1.0 - 0.35 * link.index / max(n - 1, 1)
                    link_rows.append(world.component(link_entity, Transform).row)
                    link_creature.append(i)
                    colour = np.clip(colours[i] * shade + 0.08 * (1 - shade), 0, 1)
                    link_static.append(
                        (link.radius, link.radius, link.radius, link.length / 2, *colour, 1.0)
                    )
        self.link_rows = np.array(link_rows, dtype=np.int64)
        self.link_instances = np.zeros((len(link_rows), INSTANCE_FLOATS), np.float32)
        if link_rows:
            self.link_instances[:, 7:] = np.array(link_static)
        self.skinned.build(world, self.creature_entities, self.creature_colour)
        meshed = set(self.skinned.creatures)
        self.mantle_skinned = np.array([e in meshed for e in self.creature_entities], bool)
        self.link_skinned = self.mantle_skinned[np.array(link_creature, dtype=np.int64)]

    def toggle_view(self) -> str:
        """Switch between the skinned and the capsule view; returns the new view."""
        self.view = VIEWS[(VIEWS.index(self.view) + 1) % len(VIEWS)]
        return self.view

    # -- per frame -----------------------------------------------------------------------
    def sync(self) -> None:
        """Remember the newest physics poses (the render system calls this each frame)."""
        self.previous = self.current
        self.current = (self.world.transforms.pos.copy(), self.world.transforms.quat.copy())

    def poses(self, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        """Body poses interpolated between the last two physics frames (alpha in [0, 1])."""
        (p0, q0), (p1, q1) = self.previous, self.current
        if alpha >= 1.0 or p0 is p1:
            return p1, q1
        return p0 + alpha * (p1 - p0), _nlerp(q0, q1, alpha)

    def upload(self, alpha: float = 1.0) -> None:
        """Fill and upload every instance array and the line list."""
        pos, quat = self.poses(alpha)
        if self.camera.follow is not None:
            self.camera.target = pos[self.camera.follow] * [1, 1, 0]
        skinned = self.view == "skinned"
        m = self.mantle_instances
        m[:, 0:3], m[:, 3:7] = pos[self.mantle_rows], quat[self.mantle_rows]
        self.mantles.update(m[~self.mantle_skinned] if skinned else m)
        links = self.link_instances
        links[:, 0:3], links[:, 3:7] = pos[self.link_rows], quat[self.link_rows]
        near = np.linalg.norm(links[:, 0:3] - self.camera.eye, axis=1) < LOD_DISTANCE
        capsules = ~self.link_skinned if skinned else np.ones(len(links), bool)
        self.links_near.update(links[near & capsules])
        self.links_far.update(links[~near & capsules])
        if skinned:
            self.skinned.update(pos, quat)
        self.suckers.update(self._sucker_instances())
        self.lines.update(self._line_vertices(pos))
        guides, children = fur_strands(self.world, self.fur_display)
        self.guide_ribbons.update(guides)
        self.child_ribbons.update(children)

    def _sucker_instances(self) -> np.ndarray:
        """Attached suckers (yellow) and the plugins' markers (threats): one sphere batch."""
        s = self.world.suckers
        held = np.flatnonzero(s.attached)
        markers = [m for plugin in self.world.plugins for m in plugin.render_spheres(self.world)]
        count = len(held) + sum(len(m.positions) for m in markers)
        out = np.zeros((count, INSTANCE_FLOATS), np.float32)
        out[:, 3] = 1.0
        out[: len(held), 0:3] = s.anchor[held] + [0.0, 0.0, 0.01]
        out[: len(held), 7:11] = (0.024, 0.024, 0.024, 0.0)
        out[: len(held), 11:15] = (1.0, 0.92, 0.25, 1.0)
        start = len(held)
        for marker in markers:
            end = start + len(marker.positions)
            out[start:end, 0:3] = marker.positions
            out[start:end, 7:11] = (*marker.size, 0.0)
            out[start:end, 11:15] = marker.rgba
            start = end
        return out

    def _goal_geometry(self) -> None:
        """Rings, markers and path legs between goals: rebuilt only when goals change."""
        fixed: list[np.ndarray] = []
        leaders, firsts, colours = [], [], []
        book = self.world.get_resource(GoalBook)  # None with the locomotion plugin off
        for entity in self.creature_entities:
            goals = book.path(entity) if book is not None else []
            if book is None or not goals:
                continue
            colour = np.append(self.creature_colour[entity] * 0.6 + 0.4, 1.0)
            points = book.positions(entity) + [0, 0, 0.005]
            fixed.append(_segments(points, colour))
            for goal, point in zip(goals, points, strict=True):
                fixed.append(_segments(point + self._goal_radius(goal) * CIRCLE, colour))
                fixed.append(_segments(np.array([point, point + [0, 0, 0.3]]), colour))
            leaders.append(self.world.component(entity, Transform).row)
            firsts.append(points[0])
            colours.append(colour)
        self._goal_lines = np.vstack(fixed) if fixed else np.zeros((0, 7))
        self._leader_rows = np.array(leaders, dtype=np.int64)
        self._leader_ends = np.array(firsts).reshape(-1, 3)
        self._leader_colours = np.array(colours).reshape(-1, 4)
        self._goal_version = _goal_version(self.world)

    def _line_vertices(self, pos: np.ndarray) -> np.ndarray:
        if self._goal_version != _goal_version(self.world):
            self._goal_geometry()
        # each creature's leg to its current goal moves with it: one vectorised pass
        leaders = np.empty((2 * len(self._leader_rows), 7))
        leaders[0::2, :3] = pos[self._leader_rows] * [1, 1, 0] + [0, 0, 0.005]
        leaders[1::2, :3] = self._leader_ends
        leaders[:, 3:] = np.repeat(self._leader_colours, 2, axis=0)
        segments = [self._goal_lines, leaders]
        if self.selected is not None:
            row = self.world.component(self.selected, Transform).row
            creature = self.world.component(self.selected, Creature)
            ring = pos[row] * [1, 1, 0] + [0, 0, 0.01] + creature.mantle_radius * 1.6 * CIRCLE
            segments.append(_segments(ring, np.array([1.0, 1.0, 1.0, 1.0])))
        fur = self.world.get_resource(FurData)
        if fur is not None and len(fur.guides) and self.fur_display.markers:
            segments.append(marker_lines(self.world, self.fur_display.selected_control))
        for provider in self.extra_lines:
            segments.append(provider(self.world))
        return np.vstack(segments).astype(np.float32)

    def _goal_radius(self, goal: int) -> float:
        return self.world.component(goal, Goal).radius

    def draw(self, alpha: float = 1.0) -> int:
        """Render into the off-screen target; returns the number of draw calls."""
        self.upload(alpha)
        self.target.bind()
        gl.glClearColor(*SKY, 1.0)
        gl.glClear(gl.GL_COLOR_BUFFER_BIT | gl.GL_DEPTH_BUFFER_BIT)
        gl.glEnable(gl.GL_DEPTH_TEST)
        gl.glEnable(gl.GL_CULL_FACE)
        view_projection = self.camera.view_projection()
        eye = tuple(self.camera.eye.astype(np.float32))
        calls = 0
        self.ground_program.use()
        set_matrix(self.ground_program, "u_view_projection", view_projection)
        self.ground_program["u_eye"] = eye
        gl.glDisable(gl.GL_CULL_FACE)
        calls += self.ground.draw()
        gl.glEnable(gl.GL_CULL_FACE)
        self.lit.use()
        set_matrix(self.lit, "u_view_projection", view_projection)
        self.lit["u_light"] = tuple(LIGHT.astype(np.float32))
        self.lit["u_eye"] = eye
        for mesh in (self.mantles, self.links_near, self.links_far, self.suckers):
            calls += mesh.draw()
        if self.view == "skinned":
            self.skinned_program.use()
            set_matrix(self.skinned_program, "u_view_projection", view_projection)
            self.skinned_program["u_light"] = tuple(LIGHT.astype(np.float32))
            self.skinned_program["u_eye"] = eye
            self.skinned_program["u_palette"] = 0
            calls += self.skinned.draw()
        self.line_program.use()
        set_matrix(self.line_program, "u_view_projection", view_projection)
        gl.glLineWidth(1.0)
        calls += self.lines.draw()
        if self.guide_ribbons.count or self.child_ribbons.count:
            calls += self.draw_strands()
        gl.glBindVertexArray(0)
        gl.glUseProgram(0)
        self.draw_calls = calls
        return calls

    def draw_strands(self) -> int:
        """Guides and child hairs as uploaded: one draw each, both faces (ribbons)."""
        prog = self.ribbon_program
        prog.use()
        set_matrix(prog, "u_view_projection", self.camera.view_projection())
        prog["u_light"] = tuple(LIGHT.astype(np.float32))
        prog["u_eye"] = tuple(self.camera.eye.astype(np.float32))
        pixel = 2.0 * np.tan(self.camera.fov_y / 2) * self.camera.distance / self.target.height
        prog["u_min_width"] = float(0.8 * pixel)  # about a pixel at the target's distance
        gl.glDisable(gl.GL_CULL_FACE)
        calls = self.guide_ribbons.draw() + self.child_ribbons.draw()
        gl.glEnable(gl.GL_CULL_FACE)
        return calls

    def frame_all(self) -> None:
        """Point the camera so every creature and goal is in view."""
        points = [self.world.transforms.pos]
        book = self.world.get_resource(GoalBook)
        if book is not None:
            points += [book.positions(entity) for entity in self.creature_entities]
        self.camera.follow = None
        self.camera.frame(np.vstack(points), margin=1.0)


@dataclass
class FurDisplay:
    """How fur is drawn: colour by fur or by control, guides and/or child hairs."""

    colour_by: str = "fur"
    guides: bool = True
    children: bool = True
    per_guide: int | None = None  # child hairs per guide; None: each fur's `children`
    follow: str = "neighbours"  # child hairs blend their 3 nearest guides, or "own"
    child_points: int | None = 3  # points per child hair drawn (level of detail); None: all
    markers: bool = False  # the controls' shapes (the fur tool shows them)
    selected_control: int | None = None  # a control entity, drawn highlighted


def fur_strands(world: World, display: FurDisplay) -> tuple[GuideCurves, GuideCurves]:
    """This frame's guides and child hairs as `display` asks (empty when hidden)."""
    fur = world.get_resource(FurData)  # None with the fur plugin off
    points = max(fur.points, 1) if fur is not None else 1
    empty = GuideCurves(
        np.zeros((0, points, 3), np.float32),
        np.zeros((0, 4), np.float32),
        np.zeros(0, np.float32),
        np.zeros(0, np.int64),
    )
    if fur is None or not len(fur.guides):
        return empty, empty
    guides = guide_curves(world, display.colour_by) if display.guides else empty
    if not display.children:
        return guides, empty
    dense = child_hairs(
        world, display.per_guide, follow=display.follow, points=display.child_points
    )
    if display.colour_by == "control":
        jitter = dense.colour[:, :3] / np.maximum(guide_curves(world).colour[dense.guide, :3], 1e-6)
        dense.colour = guide_curves(world, "control").colour[dense.guide]
        dense.colour[:, :3] *= jitter
    return guides, dense


def _goal_version(world: World) -> int:
    """Changes whenever any goal does (-1 without the locomotion plugin)."""
    book = world.get_resource(GoalBook)
    return -1 if book is None else int(book.version)


def _segments(polyline: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """Line-list vertices (2(n-1), 7) for a polyline (n, 3) in one colour."""
    starts, ends = polyline[:-1], polyline[1:]
    pairs = np.empty((2 * len(starts), 3))
    pairs[0::2], pairs[1::2] = starts, ends
    return np.hstack([pairs, np.tile(colour, (len(pairs), 1))])
