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

import json
import os
import struct
from typing import Any

import numpy as np

from ecs_tentacles import __version__
from ecs_tentacles.export.ground import add_gltf_ground
from ecs_tentacles.export.materials import gltf_material, take_colours
from ecs_tentacles.export.meshes import Mesh, body_mesh
from ecs_tentacles.export.names import FOLDERS, part, unique_leaf, unique_path
from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.take import Take
from ecs_tentacles.take.roster import spans

Z_UP_TO_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
_FLOAT, _USHORT, _UINT = 5126, 5123, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_GLB_MAGIC, _JSON_CHUNK, _BIN_CHUNK = 0x46546C67, 0x4E4F534A, 0x004E4942


def to_y_up_points(points: np.ndarray) -> np.ndarray:
    """(..., 3) z-up points or vectors -> y-up."""
    return np.asarray(points, dtype=np.float64) @ Z_UP_TO_Y_UP.T


def to_y_up_rotations(quat_wxyz: np.ndarray) -> np.ndarray:
    """(..., 4) z-up (w, x, y, z) quaternions -> y-up glTF (x, y, z, w), unit length."""
    q = np.asarray(quat_wxyz, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    vector = to_y_up_points(q[..., 1:])
    return np.concatenate([vector, q[..., :1]], axis=-1)


class _Buffer:
    """Binary chunk under construction: one buffer view and accessor per array."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []

    def add(self, array: np.ndarray, kind: str, target: int | None = None) -> int:
        """Append `array` (float32, uint16 or uint32), return its accessor index."""
        raw = np.ascontiguousarray(array).tobytes()
        view: dict[str, Any] = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.data += raw + b"\0" * (-len(raw) % 4)
        self.views.append(view)
        accessor: dict[str, Any] = {
            "bufferView": len(self.views) - 1,
            "componentType": {np.dtype(np.float32): _FLOAT, np.dtype(np.uint32): _UINT}.get(
                array.dtype, _USHORT
            ),
            "count": int(array.shape[0]),
            "type": kind,
        }
        if kind in ("VEC3", "SCALAR") and array.dtype == np.float32:
            flat = array.reshape(array.shape[0], -1)
            accessor["min"] = flat.min(axis=0).tolist()
            accessor["max"] = flat.max(axis=0).tolist()
        self.accessors.append(accessor)
        return len(self.accessors) - 1


def build_gltf(take: Take, locators: bool = True) -> tuple[dict[str, Any], bytes]:
    """The glTF JSON document and its binary buffer (with `locators`: sucker and goal nodes)."""
    header = take.header
    buffer = _Buffer()
    meshes: list[dict[str, Any]] = []
    mesh_of: dict[tuple[str, str, float, float, int], int] = {}
    materials: list[dict[str, Any]] = []
    node_of_body: dict[int, int] = {}
    nodes: list[dict[str, Any]] = [{"name": "World", "children": []}]
    body_nodes: list[int] = []
    translations = to_y_up_points(take.pos).astype(np.float32)
    rotations = to_y_up_rotations(take.quat).astype(np.float32)

    def node(name: str, parent: int, **fields: Any) -> int:
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
        node_of_body[index] = len(nodes)
        body_nodes.append(
            node(
                unique_leaf(info["name"]),
                parent,
                mesh=mesh_of[key],
                translation=translations[0, index].tolist(),
                rotation=rotations[0, index].tolist(),
            )
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
                node(child.pop("name"), node_of_body[parent], **child)
    ground = add_gltf_ground(take, buffer, nodes, meshes, materials, to_y_up_points)
    if ground is not None:
        nodes[0]["children"].append(ground)
    document: dict[str, Any] = {
        "asset": {
            "version": "2.0",
            "generator": f"ecs_tentacles {__version__}",
            "extras": {k: header[k] for k in ("scene", "scene_sha256", "seed", "fps")},
        },
        "scene": 0,
        "scenes": [{"name": str(header["scene"]), "nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
    }
    animation = _animation(buffer, take, body_nodes, translations, rotations)
    shown = take.visible()
    for index, root in enumerate(roots):
        scale_visibility(buffer, take, shown[:, index], nodes[root], root, animation)
    if locators:
        add_gltf_goals(take, buffer, nodes, animation)
    document["animations"] = [animation]
    document["buffers"] = [{"byteLength": len(buffer.data)}]
    document["bufferViews"] = buffer.views
    document["accessors"] = buffer.accessors
    return document, bytes(buffer.data)


def scale_visibility(
    buffer: _Buffer,
    take: Take,
    shown: np.ndarray,
    node: dict[str, Any],
    index: int,
    animation: dict[str, Any],
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
    sampler = {"input": buffer.add(times, "SCALAR"), "output": buffer.add(scales, "VEC3")}
    samplers.append({**sampler, "interpolation": "STEP"})
    channels.append({"sampler": len(samplers) - 1, "target": {"node": index, "path": "scale"}})


def sucker_nodes(
    take: Take, creature: str, joint_offsets: dict[int, float] | None = None
) -> list[tuple[int, dict[str, Any]]]:
    """(body, node) for each sucker of `creature`: a node named as USD names it, placed at
    the sucker in its body's frame (y-up), or, with `joint_offsets` (body -> the joint's
    origin along the body's x: `Skeleton.offset`), in the frame of that body's joint."""
    out = []
    for sucker in take.header["suckers"]:
        if sucker["name"].split("/", 1)[0] != creature:
            continue
        body = int(sucker["body"])
        local = np.asarray(sucker["offset"], dtype=np.float64)
        if joint_offsets is not None:
            local = local - [joint_offsets[body], 0.0, 0.0]
        point = to_y_up_points(local).astype(np.float32).tolist()
        extras = {"ecs:locator": "sucker"}  # what it is (an importer's custom property)
        out.append((body, {"name": unique_leaf(sucker["name"]), "translation": point,
                           "extras": extras}))  # fmt: skip
    return out


def add_gltf_goals(
    take: Take, buffer: _Buffer, nodes: list[dict[str, Any]], animation: dict[str, Any]
) -> None:
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
            extras = {key: value for key, value in extras.items() if value is not None}
            nodes.append({"name": leaf, "translation": point, "extras": extras})
            nodes[folders[folder]].setdefault("children", []).append(len(nodes) - 1)
            own = len(nodes) - 1
            scale_visibility(buffer, take, live[:, index], nodes[own], own, animation)


def _mesh(buffer: _Buffer, mesh: Mesh, name: str, material: int) -> dict[str, Any]:
    positions = to_y_up_points(mesh.positions).astype(np.float32)
    normals = to_y_up_points(mesh.normals).astype(np.float32)
    attributes = {
        "POSITION": buffer.add(positions, "VEC3", _ARRAY_BUFFER),
        "NORMAL": buffer.add(normals, "VEC3", _ARRAY_BUFFER),
    }
    indices = buffer.add(mesh.indices, "SCALAR", _ELEMENT_ARRAY_BUFFER)
    primitive = {"attributes": attributes, "indices": indices, "material": material, "mode": 4}
    return {"name": name, "primitives": [primitive]}


def _animation(
    buffer: _Buffer,
    take: Take,
    body_nodes: list[int],
    translations: np.ndarray,
    rotations: np.ndarray,
) -> dict[str, Any]:
    times = buffer.add(take.times.astype(np.float32), "SCALAR")
    interpolation = "LINEAR" if take.frames > 1 else "STEP"
    samplers: list[dict[str, Any]] = []
    channels: list[dict[str, Any]] = []
    for index, target in enumerate(body_nodes):
        for path, values, kind in (
            ("translation", translations[:, index], "VEC3"),
            ("rotation", rotations[:, index], "VEC4"),
        ):
            output = buffer.add(np.ascontiguousarray(values), kind)
            samplers.append({"input": times, "output": output, "interpolation": interpolation})
            channels.append(
                {"sampler": len(samplers) - 1, "target": {"node": target, "path": path}}
            )
    return {"name": part(str(take.header["scene"]), "animation"), "samplers": samplers,
            "channels": channels}  # fmt: skip


def glb_bytes(document: dict[str, Any], binary: bytes) -> bytes:
    """A GLB container: 12-byte header, JSON chunk (space-padded), BIN chunk (zero-padded)."""
    text = json.dumps(document, separators=(",", ":"), sort_keys=True, allow_nan=False).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return b"".join(
        [
            struct.pack("<III", _GLB_MAGIC, 2, total),
            struct.pack("<II", len(text), _JSON_CHUNK),
            text,
            struct.pack("<II", len(binary), _BIN_CHUNK),
            binary,
        ]
    )


def read_glb(data: bytes) -> tuple[dict[str, Any], bytes]:
    """Split a GLB into its JSON document and binary chunk (for tests and tools)."""
    magic, version, total = struct.unpack_from("<III", data, 0)
    if magic != _GLB_MAGIC or version != 2 or total != len(data):
        raise ValueError("not a glTF 2.0 binary file")
    json_length, _ = struct.unpack_from("<II", data, 12)
    document = json.loads(data[20 : 20 + json_length])
    bin_length, _ = struct.unpack_from("<II", data, 20 + json_length)
    start = 28 + json_length
    return document, data[start : start + bin_length]


def accessor_array(document: dict[str, Any], binary: bytes, index: int) -> np.ndarray:
    """Read accessor `index` of a document as a numpy array (float32 or uint16)."""
    accessor = document["accessors"][index]
    view = document["bufferViews"][accessor["bufferView"]]
    dtype = np.float32 if accessor["componentType"] == _FLOAT else np.uint16
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[accessor["type"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    flat = np.frombuffer(binary, dtype=dtype, count=accessor["count"] * width, offset=start)
    return flat.reshape(accessor["count"], width) if width > 1 else flat


def write_glb(take: Take, path: str | os.PathLike[str], locators: bool = True) -> None:
    """Write `take` as a .glb file, atomically; `TakeError` for a take glTF cannot hold.
    `locators=False` leaves the sucker and goal nodes out."""
    take.check_exportable(path)
    data = glb_bytes(*build_gltf(take, locators))
    with atomic_file(path) as handle:
        handle.write(data)
