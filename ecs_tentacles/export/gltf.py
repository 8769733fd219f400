"""Take -> binary glTF 2.0 (.glb) for game engines: one animated node per body.

Nodes mirror the USD layout and names: `World` / `<c>` / `<c>_mantle` and
`<c>_tentacles` / `<c>_t<k>` / `<c>_t<k>_link<i>` (unique: `ecs_tentacles.export.names`).
Parents carry no transform, so each body node's translation and rotation are its world
pose (a creature that comes or goes during the take has its root's scale keyed to zero
while it is not there: `scale_visibility`); one animation (`<scene>_animation`) has a
translation and a rotation channel per body (LINEAR, a key per take frame, time =
frame / fps). Bodies carry lean meshes (capsules along +x, the mantle's cylinder)
bound to their creature's material (`<c>_material`, its sandbox colour:
`ecs_tentacles.export.materials`).

Locators (on by default in the rigid form, `locators=False` leaves them out): each sucker
is a node under its link (`<c>_t<k>_link<i>_sucker<n>`, at the sucker), each goal a node
under `<c>_goals` (`<c>_goal<j>`, at the goal, its scale keyed to zero once reached);
their `extras` say what they are (`ecs:locator`: sucker or goal; a goal's `ecs:radius`).

glTF is y-up, our world z-up: everything is turned by -90 degrees about x on the
way out, (x, y, z) -> (x, z, -y) for points and for quaternion vector parts, so an
engine shows the creature standing on its ground. Written with numpy and `struct`
(the format is a JSON chunk and a binary chunk); `ecs-tentacles export` and the
tests check files with the Khronos glTF validator.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles import __version__
from ecs_tentacles.export.glb import (
    ARRAY_BUFFER,
    ELEMENT_ARRAY_BUFFER,
    GlbBuffer,
    accessor_array,
    glb_bytes,
    read_glb,
    stream_glb,
)
from ecs_tentacles.export.glb_size import refuse_large_glb
from ecs_tentacles.export.ground import add_gltf_ground
from ecs_tentacles.export.materials import gltf_material, take_colours
from ecs_tentacles.export.meshes import Mesh as BodyMesh
from ecs_tentacles.export.meshes import body_mesh
from ecs_tentacles.export.names import FOLDERS, part, unique_leaf, unique_path
from ecs_tentacles.take import Take
from ecs_tentacles.take.roster import spans

if TYPE_CHECKING:
    from typing_extensions import Unpack  # (typing's own from Python 3.12)

    from ecs_tentacles.export.gltf_types import (
        AccessorType,
        Animation,
        AnimationSampler,
        Channel,
        Document,
        Interpolation,
        Material,
        Mesh,
        Node,
        NodeFields,
        Primitive,
        TargetPath,
    )

__all__ = ["accessor_array", "build_gltf", "glb_bytes", "read_glb", "write_glb"]

Z_UP_TO_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
BLOCK_BYTES = 64 * 1024**2  # float64 temporaries of the bodies turned y-up at once
Progress = Callable[[int], object]


def to_y_up_points(points: np.ndarray) -> np.ndarray:
    """(..., 3) z-up points or vectors -> y-up."""
    y_up: np.ndarray = np.asarray(points, dtype=np.float64) @ Z_UP_TO_Y_UP.T
    return y_up


def to_y_up_rotations(quat_wxyz: np.ndarray) -> np.ndarray:
    """(..., 4) z-up (w, x, y, z) quaternions -> y-up glTF (x, y, z, w), unit length."""
    q = np.asarray(quat_wxyz, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    vector = to_y_up_points(q[..., 1:])
    return np.concatenate([vector, q[..., :1]], axis=-1)


def build_gltf(take: Take, locators: bool = True) -> tuple[Document, bytes]:
    """The glTF JSON document and its binary buffer, in memory (with `locators`: sucker
    and goal nodes)."""
    buffer = GlbBuffer()
    document = gltf_document(take, buffer, locators)
    return document, buffer.value()


def gltf_document(
    take: Take, buffer: GlbBuffer, locators: bool = True, progress: Progress | None = None
) -> Document:
    """The glTF JSON document, its arrays added to `buffer` as they are made (the bodies'
    keys a block of bodies at a time: `progress(n)` after each block of n bodies)."""
    header = take.header
    meshes: list[Mesh] = []
    mesh_of: dict[tuple[str, str, float, float, int], int] = {}
    materials: list[Material] = []
    node_of_body: dict[int, int] = {}
    nodes: list[Node] = [{"name": "World", "children": []}]
    translations = to_y_up_points(take.pos[0]).astype(np.float32)  # the rest pose: frame 0
    rotations = to_y_up_rotations(take.quat[0]).astype(np.float32)

    def node(name: str, parent: int, **fields: Unpack[NodeFields]) -> int:
        nodes.append({"name": name, **fields})
        nodes[parent].setdefault("children", []).append(len(nodes) - 1)
        return len(nodes) - 1

    def body(index: int, parent: int, material: int) -> None:
        info = header["bodies"][index]
        shape = (info["shape"], info["axis"], float(info["radius"]), float(info["length"]))
        key = (*shape, material)  # a mesh per shape and creature: the material is the mesh's
        if key not in mesh_of:
            mesh_of[key] = len(meshes)
            meshes.append(_mesh(buffer, body_mesh(*shape), info["shape"], material))
        node_of_body[index] = node(
            unique_leaf(info["name"]),
            parent,
            mesh=mesh_of[key],
            translation=translations[index].tolist(),
            rotation=rotations[index].tolist(),
        )

    roots = []
    colours = take_colours(take)
    for creature in header["creatures"]:
        name = creature["name"]
        materials.append(gltf_material(name, colours[name]))
        root = node(name, 0)
        roots.append(root)
        body(creature["mantle"], root, len(materials) - 1)
        tentacles = node(unique_leaf(f"{name}/tentacles"), root)
        for k, chain in enumerate(creature["tentacles"]):
            folder = node(unique_leaf(f"{name}/tentacles/t{k}"), tentacles)
            for index in chain:
                body(index, folder, len(materials) - 1)
    if locators:
        for creature in header["creatures"]:
            for parent, child in sucker_nodes(take, creature["name"]):
                nodes.append(child)
                nodes[node_of_body[parent]].setdefault("children", []).append(len(nodes) - 1)
    ground = add_gltf_ground(take, buffer, nodes, meshes, materials, to_y_up_points)
    if ground is not None:
        nodes[0]["children"].append(ground)
    document: Document = {
        **document_head(header, [0]),
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
    }
    animation = _animation(buffer, take, node_of_body, progress)
    shown = take.visible()
    for index, root in enumerate(roots):
        scale_visibility(buffer, take, shown[:, index], nodes[root], root, animation)
    if locators:
        add_gltf_goals(take, buffer, nodes, animation)
    document["animations"] = [animation]
    return document | buffer.fields()


def document_head(header: Mapping[str, object], roots: list[int]) -> Document:
    """What every glTF document the exporters write starts with: the asset (generator,
    and the take's scene, scene hash, seed and fps as extras) and its one scene, whose
    root nodes are `roots`."""
    return {
        "asset": {
            "version": "2.0",
            "generator": f"ecs_tentacles {__version__}",
            "extras": {k: header[k] for k in ("scene", "scene_sha256", "seed", "fps")},
        },
        "scene": 0,
        "scenes": [{"name": str(header["scene"]), "nodes": roots}],
    }


def scale_visibility(
    buffer: GlbBuffer,
    take: Take,
    shown: np.ndarray,
    node: Node,
    index: int,
    animation: Animation,
) -> None:
    """Hide node `index` (`node`: its entry) while a creature is not there
    (`ecs_tentacles.take.roster`): glTF has no visibility, so its scale is keyed to zero
    (STEP keys where `shown` changes), the way engines read a hidden object. Nothing is
    written for a creature there all along."""
    if shown.all():
        return
    keys = spans(shown)
    times = np.array([frame / take.fps for frame, _ in keys], dtype=np.float32)
    scales = np.array([[1.0] * 3 if visible else [0.0] * 3 for _, visible in keys], np.float32)
    if not keys[0][1]:
        node["scale"] = [0.0, 0.0, 0.0]  # as the animation starts
    samplers, channels = animation["samplers"], animation["channels"]
    samplers.append(
        {
            "input": buffer.add(times, "SCALAR"),
            "output": buffer.add(scales, "VEC3"),
            "interpolation": "STEP",
        }
    )
    channels.append({"sampler": len(samplers) - 1, "target": {"node": index, "path": "scale"}})


def sucker_nodes(
    take: Take, creature: str, joint_offsets: dict[int, float] | None = None
) -> list[tuple[int, Node]]:
    """(body, node) for each sucker of `creature`: a node named as USD names it, placed at
    the sucker in its body's frame (y-up), or, with `joint_offsets` (body -> the joint's
    origin along the body's x: `Skeleton.offset`), in the frame of that body's joint."""
    out: list[tuple[int, Node]] = []
    for sucker in take.header["suckers"]:
        if sucker["name"].split("/", 1)[0] != creature:
            continue
        body = int(sucker["body"])
        local = np.asarray(sucker["offset"], dtype=np.float64)
        if joint_offsets is not None:
            local = local - [joint_offsets[body], 0.0, 0.0]
        point = to_y_up_points(local).astype(np.float32).tolist()
        # what it is (an importer's custom property)
        extras: dict[str, str | float] = {"ecs:locator": "sucker"}
        out.append((body, {"name": unique_leaf(sucker["name"]), "translation": point,
                           "extras": extras}))  # fmt: skip
    return out


def add_gltf_goals(take: Take, buffer: GlbBuffer, nodes: list[Node], animation: Animation) -> None:
    """Every points track's items (the goals) as nodes under World: `<c>_goals/<c>_goal<j>`
    at the item's place (y-up), its scale keyed to zero while it is not live."""
    folders: dict[str, int] = {}
    for track in take.track_list():
        if track.kind != "points":
            continue
        where, live = (take.tracks[name] for name in track.arrays)
        for index, item in enumerate(take.header[track.key]):
            *path, leaf = unique_path(item["name"], FOLDERS | {track.folder}).split("/")
            folder = path[-1] if len(path) > 1 else track.folder
            if folder not in folders:
                folders[folder] = len(nodes)
                nodes.append({"name": folder})
                nodes[0].setdefault("children", []).append(folders[folder])
            point = to_y_up_points(where[index]).astype(np.float32).tolist()
            extras = {"ecs:locator": track.item, "ecs:radius": item.get("radius")}
            kept: dict[str, str | float] = {k: v for k, v in extras.items() if v is not None}
            nodes.append({"name": leaf, "translation": point, "extras": kept})
            nodes[folders[folder]].setdefault("children", []).append(len(nodes) - 1)
            own = len(nodes) - 1
            scale_visibility(buffer, take, live[:, index], nodes[own], own, animation)


def _mesh(buffer: GlbBuffer, mesh: BodyMesh, name: str, material: int) -> Mesh:
    positions = to_y_up_points(mesh.positions).astype(np.float32)
    normals = to_y_up_points(mesh.normals).astype(np.float32)
    attributes = {
        "POSITION": buffer.add(positions, "VEC3", ARRAY_BUFFER),
        "NORMAL": buffer.add(normals, "VEC3", ARRAY_BUFFER),
    }
    indices = buffer.add(mesh.indices, "SCALAR", ELEMENT_ARRAY_BUFFER)
    return triangle_mesh(name, attributes, indices, material)


def triangle_mesh(name: str, attributes: dict[str, int], indices: int, material: int) -> Mesh:
    """A mesh of one primitive: triangles (mode 4) of the accessors `attributes` and
    `indices`, in `material`."""
    primitive: Primitive = {
        "attributes": attributes,
        "indices": indices,
        "material": material,
        "mode": 4,
    }
    return {"name": name, "primitives": [primitive]}


def _animation(
    buffer: GlbBuffer, take: Take, node_of_body: dict[int, int], progress: Progress | None
) -> Animation:
    """One animation: a translation and a rotation channel per body, every frame keyed.
    The bodies are turned y-up a block at a time (`BLOCK_BYTES` of temporaries)."""
    times = buffer.add(take.times.astype(np.float32), "SCALAR")
    interpolation: Interpolation = "LINEAR" if take.frames > 1 else "STEP"
    samplers: list[AnimationSampler] = []
    channels: list[Channel] = []
    bodies = list(node_of_body.items())
    block = max(1, BLOCK_BYTES // (take.frames * 7 * 8 * 2))
    for start in range(0, len(bodies), block):
        chunk = bodies[start : start + block]
        index = np.array([body for body, _ in chunk])
        translations = to_y_up_points(take.pos[:, index]).astype(np.float32)
        rotations = to_y_up_rotations(take.quat[:, index]).astype(np.float32)
        for column, (_, target) in enumerate(chunk):
            keyed: tuple[tuple[TargetPath, np.ndarray, AccessorType], ...] = (
                ("translation", translations[:, column], "VEC3"),
                ("rotation", rotations[:, column], "VEC4"),
            )
            for path, values, kind in keyed:
                output = buffer.add(values, kind)
                samplers.append({"input": times, "output": output, "interpolation": interpolation})
                channels.append(
                    {"sampler": len(samplers) - 1, "target": {"node": target, "path": path}}
                )
        if progress is not None:
            progress(len(chunk))
    return {"name": part(str(take.header["scene"]), "animation"), "samplers": samplers,
            "channels": channels}  # fmt: skip


def write_glb(
    take: Take,
    path: str | os.PathLike[str],
    locators: bool = True,
    progress: Progress | None = None,
) -> None:
    """Write `take` as a .glb file, atomically, within bounded memory (the binary chunk
    is spooled to disk: `ecs_tentacles.export.glb`); `TakeError` for a take glTF cannot
    hold, `GlbTooLarge` for a file over glTF's 4 GiB (counted before any work).
    `locators=False` leaves the sucker and goal nodes out; `progress(n)`: n bodies done."""
    take.check_exportable(path)
    refuse_large_glb(take.header, path, None, locators)
    stream_glb(path, lambda buffer: gltf_document(take, buffer, locators, progress))
