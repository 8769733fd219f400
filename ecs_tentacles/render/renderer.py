"""Draws a World: the sky and the ground (`render.scenery`: the plane's grid, or the
terrain, the ground beyond it to the horizon and the obstacles), creatures, and what the
plugins hand it; distance fog in the sky's horizon colour joins the ground to the sky.
Reads the world's stores (Transform, creatures, suckers) and its plugins' hooks; writes
its off-screen target (`target`) and the `RenderView` the hooks get (`render_view`).

Creatures are drawn skinned by default (`view = "skinned"`: one continuous mesh per
creature, skinned on the GPU, all creatures in one draw; `ecs_tentacles.render.skinned`)
or as the physics sees them (`view = "capsules"`: a cylinder per mantle, a capsule per
link). Per frame: one numpy pass fills each mesh kind's instance array from the
Transform store (interpolated between the last two physics frames), one upload per
kind, one draw per kind (capsule links in two levels of detail). Draw calls do not
grow with the number of creatures.

The renderer names no feature: each frame it calls the entries plugins added to its
registries (`ecs_tentacles.render.registries`) for spheres (`Spheres`: attached
suckers, threats; one instanced batch), line segments (`Lines`: goal rings and paths,
fur control markers; one line batch with the selected creature's ring; both gathered
in `render.marks`) and their own drawing (`Draws`: fur's ribbons, with GL objects the
plugin makes and keeps in `state`), handing them a `RenderView`; "frame all" keeps
`FramedPoints` in view. The blended passes (blob shadows, line ribbons) are
`render.passes`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from pyglet import gl

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.render import marks, shaders
from ecs_tentacles.render.camera import OrbitCamera
from ecs_tentacles.render.decals import QUAD, SUCKER_DISC, shadow_instances, sucker_instances
from ecs_tentacles.render.gpu import (
    INSTANCE_FLOATS,
    InstancedMesh,
    SegmentRibbons,
    Target,
    program,
)
from ecs_tentacles.render.horizon import HORIZON, fog_range
from ecs_tentacles.render.instances import CreatureStatic, creature_links, link_instances
from ecs_tentacles.render.meshes import CAPSULE_LODS, CYLINDER_LOD, SPHERE_LOD
from ecs_tentacles.render.outlines import INSTANCE_FLOATS as RIBBON_FLOATS
from ecs_tentacles.render.outlines import RIBBON_VERTEX, ribbon_instances
from ecs_tentacles.render.passes import ribbon_pass, shadow_pass
from ecs_tentacles.render.registries import Draws, FramedPoints, RenderView
from ecs_tentacles.render.scenery import Scenery, Sight, use_lit
from ecs_tentacles.render.skinned import SkinnedCreatures
from ecs_tentacles.roster_change import RosterChange
from ecs_tentacles.skin.colours import PALETTES, Look, creature_colour, look_in_world
from ecs_tentacles.world import World

SKY = HORIZON  # what is behind everything at the horizon (the sky is drawn over it)
LIGHT = np.array([0.35, -0.45, 0.82]) / np.linalg.norm([0.35, -0.45, 0.82])
LOD_DISTANCE = 6.0  # metres from the eye beyond which links use the lean mesh
SHADOW_EVERY = 3  # a blob under every third link (each wider), and under every mantle
VIEWS = ("skinned", "capsules")


def _nlerp(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    b = np.where((np.einsum("ij,ij->i", a, b) < 0)[:, None], -b, b)
    q = a + t * (b - a)
    unit: np.ndarray = q / np.linalg.norm(q, axis=1, keepdims=True)
    return unit


class Renderer:
    """GPU objects and per-frame instance arrays for one world."""

    def __init__(self, world: World, width: int, height: int):
        self.world = world
        self.target = Target(width, height)
        self.camera = OrbitCamera(width, height)
        self.lit = program(shaders.INSTANCED_VERTEX, shaders.LIT_FRAGMENT)
        self.line_program = program(RIBBON_VERTEX, shaders.LINE_FRAGMENT)
        self.scenery = Scenery()  # the sky and the ground (`render.scenery`)
        self.skinned_program = program(shaders.SKINNED_VERTEX, shaders.LIT_FRAGMENT)
        self.skinned = SkinnedCreatures()
        self.view = "skinned"
        self.mantles = InstancedMesh(CYLINDER_LOD)
        self.links_near = InstancedMesh(CAPSULE_LODS[0])
        self.links_far = InstancedMesh(CAPSULE_LODS[1])
        self.spheres = InstancedMesh(SPHERE_LOD)  # the plugins' `Spheres` entries
        self.blob_program = program(shaders.BLOB_VERTEX, shaders.BLOB_FRAGMENT)
        self.shadows = InstancedMesh(QUAD)  # a soft blob under every mantle and link
        self.sucker_discs = InstancedMesh(SUCKER_DISC)
        # every line as an outlined ribbon: ends a and b, rgba, width in pixels
        self.lines = SegmentRibbons(RIBBON_FLOATS, ((3, 0), (3, 3), (4, 6), (1, 10)))
        self.selected: int | None = None  # creature entity (the HUD's)
        self.selection: tuple[int, ...] = ()  # every selected creature (a ring each)
        self.draw_calls = 0
        self.extra_lines: list[Callable[[World], np.ndarray]] = []  # -> (2n, 7) segments
        self.overlays = False  # editing aids wanted (the sandbox sets it while its HUD shows)
        # the clean view: none of the editor's aids (overlay entries, selection rings)
        self.clean = False
        self.show_tiers = False  # a marker per creature coloured by physics tier (render.tiers)
        # pixels on the picture's left that an opaque panel drawn after the world covers
        # (the sandbox's HUD): the world is not drawn there (`draw`)
        self.covered_left = 0
        self.state: dict[str, object] = {}  # what plugins keep here (GL objects), across worlds
        self.palette = "natural"  # the creatures' colours (`ecs_tentacles.skin.colours`)
        self.set_world(world)

    def set_world(self, world: World) -> None:
        """Draw `world` from now on (same GPU objects, new instance tables)."""
        self.world = world
        self.selected = None
        self.selection = ()
        self._colour_index: dict[int, int] = {}  # creature entity -> its place, kept
        self._looks: dict[int, Look] = {}  # creature entity -> what its colour is from
        self._static: dict[int, CreatureStatic] = {}  # creature entity -> its link table
        self.skinned.forget_all()
        self._stale = False
        self._build_static()
        self.previous = (world.transforms.pos.copy(), world.transforms.quat.copy())
        self.current = self.previous
        self.view_of_frame(*self.current)

    def roster_changed(self, change: RosterChange) -> None:
        """A creature came or went: the selection and the followed body follow now; the
        instance tables are made again before the next frame is drawn (once, however many
        creatures a scatter added), everyone keeping their colour."""
        if not change.spawned:
            self.selection = tuple(e for e in self.selection if e != change.creature)
            if self.selected == change.creature:
                self.selected = None
            follow = self.camera.follow
            if follow is not None:
                row = int(change.moved["transforms"][follow])
                self.camera.follow = row if row >= 0 else None
            self._static.pop(change.creature, None)
            self.skinned.forget(change.creature)
        self._stale = True

    def _refresh(self) -> None:
        """The instance tables and poses of the creatures there now (after a roster change)."""
        if not self._stale:
            return
        self._stale = False
        self._build_static()
        self.current = (self.world.transforms.pos.copy(), self.world.transforms.quat.copy())
        self.previous = self.current

    @property
    def creature_entities(self) -> list[int]:
        """The creatures drawn, in entity order."""
        self._refresh()
        return self._entities

    @property
    def mantle_rows(self) -> np.ndarray:
        """Each drawn creature's mantle row of the Transform store."""
        self._refresh()
        return self._mantle_rows

    # -- static per-instance data ------------------------------------------------------
    def _build_static(self) -> None:
        world = self.world
        creatures = sorted(world.query(Creature, Transform))
        self._entities = [e for e, _ in creatures]
        self._index_of = {e: i for i, e in enumerate(self._entities)}
        for entity in self._entities:  # the next place (debug colour) for a newcomer
            self._colour_index.setdefault(entity, len(self._colour_index))
            if entity not in self._looks:
                self._looks[entity] = look_in_world(world, entity, self._colour_index[entity])
        colours = np.array(
            [creature_colour(self._looks[e], self.palette) for e in self._entities]
        ).reshape(-1, 3)
        self.creature_colour = {e: colours[i] for i, e in enumerate(self._entities)}
        mantle = np.zeros((len(creatures), INSTANCE_FLOATS), np.float32)
        self._mantle_rows = np.array([t.row for _, (_, t) in creatures], dtype=np.int64)
        for i, (_, (creature, _)) in enumerate(creatures):
            r, h = creature.mantle_radius, creature.mantle_height
            mantle[i, 7:11] = (r, r, h / 2, 0.0)
            mantle[i, 11:15] = (*colours[i], 1.0)
        self.mantle_instances = mantle
        tables = []
        for (entity, (creature, _)), row in zip(creatures, self._mantle_rows, strict=True):
            if entity not in self._static:  # kept: a creature's rows stay together
                self._static[entity] = creature_links(world, creature, int(row))
            tables.append(self._static[entity])
        links = link_instances(tables, self._mantle_rows, colours)
        self.link_rows, self.link_instances = links.rows, links.instances
        link_creature, index = links.creature, links.index
        self.link_creature = link_creature  # each link's creature (index in entity order)
        self.scenery.build(ground_of(world))
        self.skinned.build(world, self._entities, self.creature_colour)
        meshed = set(self.skinned.creatures)
        self.mantle_skinned = np.array([e in meshed for e in self._entities], bool)
        self.link_skinned = self.mantle_skinned[link_creature]
        # shadows: every mantle and every SHADOW_EVERY-th link (blended quads are what
        # software GL pays for), by transform row; suckers: their links' sizes
        shadowed = index % SHADOW_EVERY == 0
        self.shadow_rows = np.concatenate([self._mantle_rows, self.link_rows[shadowed]])
        self.shadow_radii = np.concatenate(
            [mantle[:, 7], SHADOW_EVERY * self.link_instances[shadowed, 7]]
        ).astype(np.float64)
        radius_of_row = np.zeros(len(world.transforms))
        radius_of_row[self.link_rows] = self.link_instances[:, 7]
        suckers = world.suckers
        self.sucker_radii = radius_of_row[suckers.link_row[: len(suckers)]]

    def set_palette(self, palette: str) -> None:
        """Colour the creatures from `palette` ("natural" or "debug") from the next frame."""
        if palette not in PALETTES:
            raise ValueError(f"palette must be one of {', '.join(PALETTES)}, got {palette!r}")
        if palette == self.palette:
            return
        self.palette = palette
        self._stale = True  # the instance tables are made again, in the new colours

    def toggle_view(self) -> str:
        """Switch between the skinned and the capsule view; returns the new view."""
        self.view = VIEWS[(VIEWS.index(self.view) + 1) % len(VIEWS)]
        return self.view

    # -- per frame -----------------------------------------------------------------------
    def sync(self) -> None:
        """Remember the newest physics poses (the render system calls this each frame)."""
        self._refresh()
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
        self._fill(*self._posed(alpha))

    def _posed(self, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        """This frame's body poses (`poses`), the camera's target on the ground under the
        followed mantle if one is (the view depends on it)."""
        self._refresh()
        pos, quat = self.poses(alpha)
        if self.camera.follow is not None:
            under = pos[self.camera.follow]
            height = ground_of(self.world).height(under[None, :2])[0]
            self.camera.target = np.array([under[0], under[1], height])
        return pos, quat

    def _fill(self, pos: np.ndarray, quat: np.ndarray) -> None:
        """Every instance array and the line list for body poses `pos`, `quat`, uploaded."""
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
        camera = self.camera
        per_metre = camera.per_metre
        if skinned:
            self.skinned.choose_detail(pos, camera.eye, per_metre)
            self.skinned.update(pos, quat)
        self.view_of_frame(pos, quat)
        ground = ground_of(self.world)
        self.shadows.update(
            shadow_instances(ground, pos[self.shadow_rows], self.shadow_radii, LIGHT)
        )
        suckers = self.world.suckers
        n = len(suckers)
        self.sucker_discs.update(
            sucker_instances(
                pos, quat, suckers.link_row[:n], suckers.offset[:n], self.sucker_radii,
                suckers.attached[:n],
            )
        )  # fmt: skip
        self.spheres.update(self._sphere_instances())
        self.lines.update(ribbon_instances(self._line_vertices(pos)))

    def view_of_frame(self, pos: np.ndarray, quat: np.ndarray) -> RenderView:
        """The `RenderView` the plugins' hooks get this frame (kept in `render_view`)."""
        camera = self.camera
        pixel = 2.0 * np.tan(camera.fov_y / 2) * camera.distance / self.target.height
        self.render_view = RenderView(
            pos=pos,
            quat=quat,
            creatures=self.creature_entities,
            colours=self.creature_colour,
            eye=camera.eye,
            view_projection=camera.view_projection(),
            light=LIGHT,
            pixel=float(pixel),
            per_metre=camera.per_metre,
            overlays=self.overlays and not self.clean,
            clean=self.clean,
            selected=self.selected,
            selection=self.selection,
            state=self.state,
        )
        return self.render_view

    def _sphere_instances(self) -> np.ndarray:
        """The plugins' spheres (attached suckers, threats): one instanced batch."""
        return marks.sphere_instances(self.world, self.clean)

    def _line_vertices(self, pos: np.ndarray) -> np.ndarray:
        """The plugins' line segments, a ring round each selected creature, `extra_lines`
        (in the clean view, the `Lines` entries' and `extra_lines` only)."""
        segments = marks.plugin_segments(self.world, self.render_view, self.clean)
        chosen = self.selection or ((self.selected,) if self.selected is not None else ())
        if chosen and not self.clean:  # one ring round each, in one pass
            drawn = [self._index_of[e] for e in chosen if e in self._index_of]
            mantles = pos[self._mantle_rows[drawn]]
            centres = np.column_stack([mantles[:, :2], np.zeros(len(drawn))])
            reach = marks.reach(
                pos, self.mantle_instances[:, 7], self._mantle_rows, self.link_rows,
                self.link_creature, self.link_instances[:, 7],
            )  # fmt: skip
            # round the tentacles, not under them
            segments.append(marks.selection_rings(centres, reach[drawn], ground_of(self.world)))
        for provider in self.extra_lines:
            segments.append(provider(self.world))
        return np.vstack(segments).astype(np.float32)

    def draw(self, alpha: float = 1.0) -> int:
        """Render into the off-screen target; returns the number of draw calls."""
        pos, quat = self._posed(alpha)
        self.target.bind()
        covered = min(max(int(self.covered_left), 0), self.target.width)
        if covered:  # what the panel hides is neither cleared nor drawn (scissored off)
            gl.glEnable(gl.GL_SCISSOR_TEST)
            gl.glScissor(covered, 0, self.target.width - covered, self.target.height)
        gl.glClearColor(*SKY, 1.0)
        gl.glClear(gl.GL_COLOR_BUFFER_BIT | gl.GL_DEPTH_BUFFER_BIT)
        gl.glEnable(gl.GL_DEPTH_TEST)
        gl.glEnable(gl.GL_CULL_FACE)
        view_projection = self.camera.view_projection()
        eye = tuple(self.camera.eye.astype(np.float32))
        fog = fog_range(self.camera.distance)
        ground = ground_of(self.world)
        sight = Sight(view_projection, eye, LIGHT, fog, grid=not self.clean)
        calls = self.scenery.draw_kept(self.target, ground, sight)
        # the ground is sent to be rasterised (software GL's threads fill it while this
        # one fills the creatures' arrays: about 4 ms less of a crowd's 50 ms frame)
        gl.glFlush()
        self._fill(pos, quat)
        calls += shadow_pass(self.blob_program, self.shadows, view_projection)
        use_lit(self.lit, view_projection, LIGHT, eye, fog)
        for mesh in (self.mantles, self.links_near, self.links_far, self.spheres):
            calls += mesh.draw()
        calls += self.sucker_discs.draw()
        if self.view == "skinned":
            use_lit(self.skinned_program, view_projection, LIGHT, eye, fog)
            self.skinned_program["u_palette"] = 0
            calls += self.skinned.draw()
        calls += ribbon_pass(
            self.line_program, self.lines, view_projection, eye, self.camera.per_metre
        )
        for draw in self.world.registry(Draws):  # what spheres and lines cannot say (fur)
            calls += draw(self.world, self.render_view)
        gl.glBindVertexArray(0)
        gl.glUseProgram(0)
        gl.glDisable(gl.GL_SCISSOR_TEST)
        self.draw_calls = calls
        return calls

    def frame_all(self) -> None:
        """Point the camera so every creature and what plugins point at (goals) is in view."""
        points = [self.world.transforms.pos]
        for framed in self.world.registry(FramedPoints):
            extra = framed(self.world)
            if extra is not None:
                points.append(np.asarray(extra, dtype=np.float64).reshape(-1, 3))
        self.camera.follow = None
        self.camera.fit(np.vstack(points))

    def follow(self, creature: int, span: float = 3.0) -> None:
        """Keep `creature` at the centre of the picture, near enough that its body and
        tentacles fill about 1 / `span` of it."""
        index = self._index_of[creature]
        pos = self.current[0]
        links = self.link_rows[self.link_creature == index]
        rows = np.concatenate([[self.mantle_rows[index]], links])
        self.camera.follow = None
        self.camera.fit(pos[rows])
        self.camera.distance *= span
        self.camera.follow = int(self.mantle_rows[index])
        self.upload()  # the target on the creature now
