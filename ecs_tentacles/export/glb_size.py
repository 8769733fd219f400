"""The bytes a glb will hold, counted from shapes before any work: at most, never less.

    size = glb_size(shapes_of_header(take.header), detail, keys, locators)
    size.total(frames)        # bytes of the file, at most
    size.most_frames()        # the most frames a glb of these creatures holds

Read from a take's header (`shapes_of_header`: `export` checks a take before reading
its frames) or from a loaded scene (`shapes_of_scene`: `bake` checks before it builds
anything). What it counts, mirroring the writers (`export.gltf`, `export.skinned_gltf`):

- the binary chunk exactly where shapes decide it: every key of every channel (rigid: a
  translation and a rotation per body a frame; skinned: a rotation per joint and the
  root's translation), the meshes (rigid: one per body shape and creature; skinned: one
  per creature, built once per mesh topology, `skin.mesh.topology`), the inverse bind
  matrices and the ground's meshes;
- at most, where the data decides: reduced keys as if every key were kept, each
  channel with its own key times; a creature that comes and goes (the take's roster)
  or a goal locator keyed at every frame; each skin's texture as an uncompressed PNG;
- the JSON at its widest (`export.glb_json`): every number as wide as it can be
  written (indices as wide as the most items of a kind, byte counts as the binary
  chunk, 24-character floats), every name as the writers make it (a sucker's or goal's
  at its longest).

Not counted from a scene (the take's header knows them, and the writers check it before
writing): the terrain's meshes, creatures spawned and goals added while baking.

`glb_problem` says, in one line, why a glb of that size cannot be written and what fits;
`refuse_large_glb` raises it (`GlbTooLarge`) for a take about to be exported. Blender's
glTF importer holds far more than the file (`GlbSize.blender_bytes`, measured):
`glb_note` says so, in one line, when that is more than the machine's memory.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import psutil

from ecs_tentacles.export.glb import GLB_MAX_BYTES, GlbTooLarge
from ecs_tentacles.export.glb_json import JsonCount
from ecs_tentacles.export.meshes import body_mesh
from ecs_tentacles.scene.construction import tentacle_angles, tentacle_params, tentacle_shape
from ecs_tentacles.skin.mesh import Detail, creature_mesh, split_by_uv, topology
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.skin.skeleton import SkinLayout, build_skeleton, skin_layout
from ecs_tentacles.take.tracks import tracks_of

# Blender 5.0.1's glTF importer, measured on 64 creatures (301 and 901 frames skinned,
# 51 and 101 MB: 1.36 and 3.14 GB peak; 301 frames rigid, 50 MB: 2.12 GB): about 35 bytes
# of memory for each byte of keys (40 rigid: an object per body), 7 for each byte of the
# rest, 0.34 GB to start with
BLENDER_BASE_BYTES = 340 * 10**6
BLENDER_PER_KEY_BYTE = {"skinned": 35, "rigid": 40}
BLENDER_PER_OTHER_BYTE = 7
PNG_BYTES = 64 * (64 * 3 + 1) * 1001 // 1000 + 128  # a 64 x 64 RGB PNG, stored, at most
MAX_SKIN_VERTICES = 65535  # a skinned mesh's triangles index its vertices in 16 bits
SKIN_VERTEX_BYTES = 12 + 12 + 8 + 8 + 16  # position, normal, uv, 4 joints (uint16), weights


@dataclass(frozen=True)
class CreatureShape:
    """A creature as the glb writers see it: name, mantle (radius, height), each
    tentacle's link lengths and radii, its suckers and goals (locators)."""

    name: str
    mantle: tuple[float, float]
    tentacles: tuple[tuple[tuple[float, ...], tuple[float, ...]], ...]
    suckers: int
    goals: int

    @property
    def bodies(self) -> int:
        return 1 + sum(len(lengths) for lengths, _ in self.tentacles)

    def layout(self) -> SkinLayout:
        """The skin layout (as `skin.skeleton.creature_skeleton` makes it from a take)."""
        angles = tentacle_angles(len(self.tentacles))
        pairs = zip(angles, self.tentacles, strict=True)
        tentacles = [(float(a), list(lengths), list(radii)) for a, (lengths, radii) in pairs]
        return skin_layout(self.name, *self.mantle, tentacles)

    def body_shapes(self) -> set[tuple[str, str, float, float]]:
        """The distinct (shape, axis, radius, length) of its bodies: a rigid mesh each."""
        shapes = {("cylinder", "Z", *self.mantle)}
        for lengths, radii in self.tentacles:
            shapes |= {("capsule", "X", r, n) for n, r in zip(lengths, radii, strict=True)}
        return shapes


@dataclass(frozen=True)
class GlbShapes:
    """What a glb's size depends on besides the frames: the creatures, whether they come
    and go (`roster`), the ground's meshes (vertices, triangles) and the scene's name."""

    creatures: tuple[CreatureShape, ...]
    frames: int
    roster: bool = False
    ground: tuple[tuple[int, int], ...] = ()
    scene: str = ""


def shapes_of_header(header: Mapping[str, Any]) -> GlbShapes:
    """The shapes of a take from its (checked) header alone: no frame is read."""
    bodies = header["bodies"]
    suckers: dict[str, int] = {}
    for sucker in header["suckers"]:
        creature = str(sucker["name"]).split("/", 1)[0]
        suckers[creature] = suckers.get(creature, 0) + 1
    goals: dict[int, int] = {}  # every points track's items (goals), by creature
    for track in tracks_of(dict(header)):
        for item in header[track.key] if track.kind == "points" else ():
            index = item.get("creature")
            owner = index if isinstance(index, int) else 0
            goals[owner] = goals.get(owner, 0) + 1
    creatures = []
    for c, entry in enumerate(header["creatures"]):
        mantle = bodies[entry["mantle"]]
        chains = tuple(
            (
                tuple(float(bodies[i]["length"]) for i in chain),
                tuple(float(bodies[i]["radius"]) for i in chain),
            )
            for chain in entry["tentacles"]
        )
        name = str(entry["name"])
        shape = (float(mantle["radius"]), float(mantle["length"]))
        creatures.append(CreatureShape(name, shape, chains, suckers.get(name, 0), goals.get(c, 0)))
    ground = tuple(
        (int(mesh["vertices"]), int(mesh["triangles"]))
        for mesh in (header.get("ground") or {}).get("meshes", [])
    )
    return GlbShapes(
        tuple(creatures), int(header["frames"]), bool(header.get("roster")), ground,
        str(header.get("scene", "")),
    )  # fmt: skip


def shapes_of_scene(scene: Mapping[str, Any], frames: int) -> GlbShapes:
    """The shapes of a bake of a loaded scene (defaults filled in) `frames` frames long,
    as the world builds them (`scene.construction.tentacle_shape`)."""
    creatures = []
    for c, creature in enumerate(scene["creatures"]):
        mantle = creature["mantle"]
        radius, height = float(mantle["radius"]), float(mantle["height"])
        tentacles = creature["tentacles"]
        chains, suckers = [], 0
        for k in range(tentacles["count"]):
            params = tentacle_params(tentacles, k)
            shape = tentacle_shape(radius, params["link_length"], params["link_radius"],
                                   params["links"], params["end_scale"])  # fmt: skip
            chains.append((tuple(map(float, shape.lengths)), tuple(map(float, shape.radii))))
            suckers += params["links"] if params.get("suckers") == "every_link" else 1
        name = str(creature.get("name", f"creature_{c}"))
        goals = len(creature.get("goals") or [])
        creatures.append(CreatureShape(name, (radius, height), tuple(chains), suckers, goals))
    return GlbShapes(tuple(creatures), frames, scene=str(scene.get("name", "")))


def _pad(size: int) -> int:
    return size + (-size % 4)


def _rigid_mesh_bytes(shape: tuple[str, str, float, float]) -> int:
    mesh = _body_mesh_counts(shape)
    return 2 * _pad(12 * mesh[0]) + _pad(2 * mesh[1])


@functools.lru_cache(maxsize=1024)
def _body_mesh_counts(shape: tuple[str, str, float, float]) -> tuple[int, int]:
    mesh = body_mesh(*shape)
    return len(mesh.positions), len(mesh.indices)


def skin_mesh_counts(layout: SkinLayout, detail: Detail) -> tuple[int, int]:
    """(vertices, triangles) of a creature's skinned glTF mesh (split where its UVs
    differ), built once per mesh topology."""
    return _skin_counts(topology(layout, detail), layout)


_skin_cache: dict[tuple[object, ...], tuple[int, int]] = {}


def _skin_counts(key: tuple[object, ...], layout: SkinLayout) -> tuple[int, int]:
    if key not in _skin_cache:
        detail = key[0]
        assert isinstance(detail, Detail)
        joints = 1 + sum(len(t.lengths) for t in layout.tentacles)
        mesh = creature_mesh(build_skeleton(layout, np.arange(joints)), detail)
        source, _, triangles = split_by_uv(mesh)
        if len(_skin_cache) >= 4096:
            _skin_cache.clear()
        _skin_cache[key] = (len(source), len(triangles))
    return _skin_cache[key]


@dataclass(frozen=True)
class GlbSize:
    """A glb's bytes at most: `fixed` whatever the frames (meshes, JSON), `per_frame`
    for every frame (keys); what it holds (`creatures`, `frames`, `form`)."""

    fixed: int
    per_frame: int
    creatures: int
    frames: int
    form: str  # "rigid" or "skinned"
    mesh_problem: str | None = None  # a skinned mesh past glTF's 16-bit indices here

    def total(self, frames: int | None = None) -> int:
        """Bytes of the file at `frames` frames (the take's by default), at most."""
        return self.fixed + self.per_frame * (self.frames if frames is None else frames)

    def blender_bytes(self) -> int:
        """About the memory Blender's glTF importer holds to import this glb (measured:
        `BLENDER_PER_KEY_BYTE` for each byte of keys, `BLENDER_PER_OTHER_BYTE` the rest)."""
        keys, per_key = self.per_frame * self.frames, BLENDER_PER_KEY_BYTE[self.form]
        return BLENDER_BASE_BYTES + per_key * keys + BLENDER_PER_OTHER_BYTE * self.fixed

    def most_frames(self) -> int:
        """The most frames a glb of these creatures holds (0: not even one)."""
        room = GLB_MAX_BYTES - self.fixed
        return max(0, room // self.per_frame) if self.per_frame else 0


@functools.lru_cache(maxsize=8)
def glb_size(
    shapes: GlbShapes,
    detail: Detail | None = None,
    keys: Keys | None = None,
    locators: bool | None = None,
) -> GlbSize:
    """The size of a glb of `shapes`: skinned with `detail` (and `keys`), rigid without;
    with `locators` (None: the form's default, on when rigid) sucker and goal nodes."""
    skinned = detail is not None
    locators = (not skinned) if locators is None else locators
    reduced = skinned and (keys or Keys()).mode == "reduced"
    count = JsonCount()
    count.add("document")
    count.name(shapes.scene, 3)  # the scene's name, the asset's extras, the animation's
    count.name("_animation")
    count.add("folder")  # World
    fixed = per_frame = 0
    if not reduced:  # one key-time accessor shared by every channel
        per_frame += 4
        count.add("scalar")
        count.add("view")
    for creature in shapes.creatures:
        per = (_skinned if skinned else _rigid)(creature, count, detail, reduced)
        fixed, per_frame = fixed + per[0], per_frame + per[1]
        if shapes.roster:  # scale keys while it is not there: at most one a frame
            per_frame += 16
            _visibility(count)
        if locators:
            per_frame += 16 * creature.goals  # a goal's scale keys: at most one a frame
            _locators(creature, count)
    for vertices, triangles in shapes.ground:
        fixed += 2 * _pad(12 * vertices) + _pad(12 * triangles)
        count.add("colour")
        count.add("rigid_mesh")
        count.add("mesh_node", 2)
        count.name("g" * 100, 3)  # `<ground>/<mesh>` for its material, mesh and node
        count.add("child", 2)
        count.add("vec3", 3)
        count.add("view", 3)
    if shapes.ground:
        count.add("folder")
        count.add("child")
        count.name("g" * 100)
    binary = fixed + per_frame * shapes.frames
    fixed += 12 + 8 + _pad(count.bound(binary)) + 8
    form = "skinned" if skinned else "rigid"
    problem = None
    if skinned:
        assert detail is not None
        for creature in shapes.creatures:
            vertices, _ = skin_mesh_counts(creature.layout(), detail)
            if vertices > MAX_SKIN_VERTICES:  # as the writer says it (`skinned_gltf._mesh`)
                problem = (
                    f"creature {creature.name}: {vertices} skinned vertices, over glTF's"
                    " 16-bit indices here; use fewer rings per link or sides"
                )
                break
    return GlbSize(fixed, per_frame, len(shapes.creatures), shapes.frames, form, problem)


def _rigid(
    creature: CreatureShape, count: JsonCount, detail: Detail | None, reduced: bool
) -> tuple[int, int]:
    """Bytes (whatever the frames, each frame) of a rigid creature; its JSON counted."""
    shapes = creature.body_shapes()
    bodies = creature.bodies
    name = creature.name
    count.add("folder", 2 + len(creature.tentacles))  # its root, tentacles and each tentacle
    count.add("body", bodies)
    count.add("child", bodies + 3 + len(creature.tentacles))
    for suffix in ("", "_tentacles", "_mantle", "_material"):
        count.name(name + suffix)
    for k, (lengths, _) in enumerate(creature.tentacles):
        count.name(f"{name}_t{k}")
        for i in range(len(lengths)):
            count.name(f"{name}_t{k}_link{i}")
    count.add("colour")
    count.add("rigid_mesh", len(shapes))
    count.add("vec3", 2 * len(shapes))
    count.add("plain", len(shapes))
    count.add("view", 3 * len(shapes))
    count.add("sampler", 2 * bodies)
    count.add("channel", 2 * bodies)
    count.add("vec3", bodies)  # translations, with their bounds
    count.add("plain", bodies)  # rotations
    count.add("view", 2 * bodies)
    return sum(_rigid_mesh_bytes(shape) for shape in shapes), 28 * bodies


def _skinned(
    creature: CreatureShape, count: JsonCount, detail: Detail | None, reduced: bool
) -> tuple[int, int]:
    """Bytes (whatever the frames, each frame) of a skinned creature; its JSON counted."""
    assert detail is not None
    bodies = creature.bodies
    name = creature.name
    vertices, triangles = skin_mesh_counts(creature.layout(), detail)
    count.add("folder")  # <c>_skeleton
    count.add("joint", bodies)
    count.add("skin_node")
    count.add("child", 2 * bodies + 2)  # the joints' children and the skin's joints, roots
    for suffix in ("_skeleton", "", "_material", "_skin", "/skin"):
        count.name(name + suffix)
    count.name("mantle")
    for k, (lengths, _) in enumerate(creature.tentacles):
        for i in range(len(lengths)):
            count.name(f"t{k}_link{i}")
    count.add("skin")
    count.add("plain", 5)  # inverse bind matrices, uv, joints, weights, indices
    count.add("vec3", 2)  # positions, normals (with their bounds)
    count.add("view", 8)  # the accessors' and the image's
    count.add("image")
    count.add("texture")
    count.add("textured")
    count.add("skin_mesh")
    count.add("sampler", bodies + 1)
    count.add("channel", bodies + 1)
    count.add("plain", bodies)  # rotations
    count.add("vec3")  # the root's translations
    count.add("view", bodies + 1)
    fixed = 64 * bodies + _pad(PNG_BYTES)  # inverse bind matrices, texture
    fixed += SKIN_VERTEX_BYTES * vertices + _pad(6 * triangles)
    per_frame = 16 * bodies + 12
    if reduced:  # each channel its own key times, at most
        per_frame += 4 * (bodies + 1)
        count.add("scalar", bodies + 1)
        count.add("view", bodies + 1)
    return fixed, per_frame


def _visibility(count: JsonCount) -> None:
    """A node's scale keys (STEP): sampler, channel, times and values."""
    count.add("sampler")
    count.add("channel")
    count.add("scalar")
    count.add("vec3")
    count.add("view", 2)
    count.add("scale_key")


def _locators(creature: CreatureShape, count: JsonCount) -> None:
    """A creature's sucker nodes, its goals' nodes (keyed to hide) and their folder."""
    count.add("sucker", creature.suckers)
    count.add("goal", creature.goals)
    count.add("folder")  # <c>_goals
    count.add("child", creature.suckers + creature.goals + 1)
    count.name(f"{creature.name}_goals")
    longest = max((len(lengths) for lengths, _ in creature.tentacles), default=0)
    tentacles = len(creature.tentacles)
    count.name(f"{creature.name}_t{tentacles}_link{longest}_sucker{longest}", creature.suckers)
    count.name(f"{creature.name}_goal{creature.goals}", creature.goals)
    for _ in range(creature.goals):
        _visibility(count)


def _gb(size: float) -> str:
    return f"{size / 1e9:,.1f} GB" if size >= 1e8 else f"{size / 1e6:,.0f} MB"


def glb_problem(
    path: str | os.PathLike[str], size: GlbSize, fits: Sequence[str], verb: str = "bake"
) -> str | None:
    """Why a glb of `size` cannot be written to `path` (one line), or None when it fits.
    `fits`: the outputs that would hold the same shot instead (`verb` to them)."""
    if size.mesh_problem:
        return size.mesh_problem
    total = size.total()
    if total <= GLB_MAX_BYTES:
        return None
    most = size.most_frames()
    if most >= 2:
        fewer = f"fewer frames or creatures (at most {most:,} frames at this size)"
    elif size.form == "skinned":
        fewer = "fewer creatures or a lighter mesh (--rings-per-link, --sides: not one frame fits)"
    else:
        fewer = "fewer creatures (not one frame fits at this size)"
    advice = f"{verb} to {' or '.join(fits)}, or {fewer}" if fits else f"bake {fewer}"
    return (
        f"{path}: the glb would be up to {_gb(total)} ({size.creatures:,} creatures x"
        f" {size.frames:,} frames, {size.form}); a glb holds at most {_gb(GLB_MAX_BYTES)}"
        f" (4 GiB: its lengths are 32-bit), and Blender's glTF importer would need about"
        f" {_gb(size.blender_bytes())} of memory for it: {advice}"
    )


def glb_note(path: str | os.PathLike[str], size: GlbSize, memory: int | None = None) -> str | None:
    """A note (one line) when a glb of `size` fits glTF but Blender's glTF importer would
    need more than `memory` (this machine's, by default) to open it, else None."""
    memory = psutil.virtual_memory().total if memory is None else memory
    needs = size.blender_bytes()
    if size.total() > GLB_MAX_BYTES or size.mesh_problem or needs <= memory:
        return None
    return (
        f"{path}: up to {_gb(size.total())}; Blender's glTF importer would need about"
        f" {_gb(needs)} of memory to open it, more than the {_gb(memory)} here: for Blender,"
        " write .usdc, or fewer frames or creatures"
    )


def refuse_large_glb(
    header: Mapping[str, object],
    path: str | os.PathLike[str],
    detail: Detail | None,
    locators: bool | None,
    keys: Keys | None = None,
) -> None:
    """Raise `GlbTooLarge` (one line, `glb_problem`) when a glb of the take `header`
    describes would pass glTF's 4 GiB; counted from the header alone."""
    size = glb_size(shapes_of_header(header), detail, keys, locators)
    problem = glb_problem(path, size, (".usdc",), "export")
    if problem:
        raise GlbTooLarge(problem)
