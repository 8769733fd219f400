"""Take -> binary glTF (.glb) with skinned creatures: a skin per creature, its joints
animated by rotation keys (and the root by translation keys).

    scene nodes: World -> <c>_skeleton -> mantle -> t0_link0 -> t0_link1 ...   (joints)
                 <c>_skin   {mesh, skin}   (a root node: glTF ignores the transform of
                                            a skinned mesh's node)
Named as the USD export names them (`ecs_tentacles.export.names`: Blender makes the
same armature, mesh and action names from either). Joint nodes carry their rest
(bind) transforms; one animation, `take`, drives every creature: a rotation channel
per joint and a translation channel on each mantle, each with its own key times when
keys are reduced (one animation, not one per creature: Blender's importer plays only
the first animation of a file and stashes the others in muted NLA tracks, and game
engines read one animation as one clip). The mesh: POSITION, NORMAL, TEXCOORD_0 (a vertex is split
where its UVs differ), JOINTS_0/WEIGHTS_0 (two influences used of four), bound to the
creature's material `<c>_material`: a texture of its sandbox colour
(`ecs_tentacles.export.materials`). Everything is turned to glTF's y-up like the rigid
form (`ecs_tentacles.export.gltf`).

Locators (suckers and goals) only with `locators=True` (`--locators`): each sucker a
node under its link's joint (so it follows the joint), each goal a node under
`<c>_goals`, as in the rigid form.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.export.glb import (
    ARRAY_BUFFER,
    ELEMENT_ARRAY_BUFFER,
    GlbBuffer,
    stream_glb,
)
from ecs_tentacles.export.glb_size import MAX_SKIN_VERTICES, refuse_large_glb
from ecs_tentacles.export.gltf import (
    Z_UP_TO_Y_UP,
    Progress,
    add_gltf_goals,
    document_head,
    scale_visibility,
    sucker_nodes,
    to_y_up_points,
    to_y_up_rotations,
    triangle_mesh,
)
from ecs_tentacles.export.ground import add_gltf_ground
from ecs_tentacles.export.materials import gltf_material, skin_texture, take_colours
from ecs_tentacles.export.names import part
from ecs_tentacles.skin.keys import KeyReport
from ecs_tentacles.skin.mesh import SkinMesh, split_by_uv
from ecs_tentacles.skin.rig import KeyTally, Skin, SkinnedCreature, rig_creature
from ecs_tentacles.take import Take

if TYPE_CHECKING:
    from ecs_tentacles.export.gltf_types import (
        AccessorType,
        Animation,
        Document,
        Image,
        Interpolation,
        Material,
        Mesh,
        Node,
        TargetPath,
    )
    from ecs_tentacles.export.gltf_types import (
        Skin as GltfSkin,
    )

__all__ = ["build_skinned_gltf", "split_by_uv", "write_skinned_glb"]

_TURN = np.eye(4)
_TURN[:3, :3] = Z_UP_TO_Y_UP


def write_skinned_glb(
    take: Take,
    path: str | os.PathLike[str],
    skin: Skin | None = None,
    locators: bool = False,
    progress: Progress | None = None,
) -> KeyReport:
    """Write `take` as a skinned .glb atomically, within bounded memory (one creature's
    rig at a time, the binary chunk spooled to disk); returns the key counts and errors.
    `skin`: the mesh's detail and the keys kept (None: `Skin()`'s defaults). `GlbTooLarge`
    for a file over glTF's 4 GiB, counted before any work. With `locators`, suckers and
    goals are nodes too (the module doc); `progress(1)` after each creature."""
    skin = skin or Skin()
    refuse_large_glb(take.header, path, skin.detail, locators, skin.keys)
    reports: list[KeyReport] = []

    def document(buffer: GlbBuffer) -> Document:
        made, report = skinned_document(take, buffer, skin, locators, progress)
        reports.append(report)
        return made

    stream_glb(path, document)
    return reports[0]


def build_skinned_gltf(
    take: Take, skin: Skin | None = None, locators: bool = False
) -> tuple[Document, bytes, KeyReport]:
    """The glTF JSON document, its binary buffer (in memory) and the key report."""
    buffer = GlbBuffer()
    document, report = skinned_document(take, buffer, skin, locators)
    return document, buffer.value(), report


def skinned_document(
    take: Take,
    buffer: GlbBuffer,
    skin: Skin | None = None,
    locators: bool = False,
    progress: Progress | None = None,
) -> tuple[Document, KeyReport]:
    """The glTF JSON document and the key report, the arrays added to `buffer` one
    creature at a time (each creature's rig dropped before the next is made)."""
    skin = skin or Skin()
    header = take.header
    tally = KeyTally(take.frames)
    nodes: list[Node] = [{"name": "World", "children": []}]
    roots = [0]
    meshes: list[Mesh] = []
    skins: list[GltfSkin] = []
    colours = take_colours(take)
    materials: list[Material] = []
    images: list[Image] = []
    animation: Animation = {"name": "take", "samplers": [], "channels": []}
    times: dict[bytes, int] = {}
    shown = take.visible()
    for number in range(len(header["creatures"])):
        creature = tally.add(rig_creature(take, number, skin.detail, skin.keys))
        skeleton = creature.skeleton
        holder = len(nodes)
        nodes.append({"name": part(skeleton.layout.name, "skeleton"), "children": []})
        nodes[0]["children"].append(holder)
        first = len(nodes)
        rotation = to_y_up_rotations(skeleton.rest_rotation).astype(np.float32)
        translation = to_y_up_points(skeleton.rest_translation).astype(np.float32)
        for j, name in enumerate(skeleton.leaf_names):
            nodes.append(
                {
                    "name": name,
                    "rotation": rotation[j].tolist(),
                    "translation": translation[j].tolist(),
                }
            )
            parent = skeleton.parents[j]
            owner = nodes[holder if parent < 0 else first + parent]
            owner.setdefault("children", []).append(first + j)
        bind = _TURN @ skeleton.bind @ _TURN.T
        inverse = np.linalg.inv(bind).transpose(0, 2, 1).reshape(-1, 16)  # column-major
        skins.append(
            {
                "name": skeleton.layout.name,
                "joints": list(range(first, first + len(skeleton.names))),
                "skeleton": first,
                "inverseBindMatrices": buffer.add(inverse.astype(np.float32), "MAT4"),
            }
        )
        name = skeleton.layout.name
        images.append({"bufferView": buffer.view(skin_texture(colours[name])),
                       "mimeType": "image/png"})  # fmt: skip
        materials.append(gltf_material(name, colours[name], texture=len(images) - 1))
        meshes.append(_mesh(buffer, creature.mesh, name, len(materials) - 1))
        roots.append(len(nodes))
        nodes.append(
            {
                "name": part(skeleton.layout.name, "skin"),
                "mesh": len(meshes) - 1,
                "skin": len(skins) - 1,
            }
        )
        _channels(buffer, take, creature, first, animation, times)
        # while the creature is not there: its root joint (and so its skin) scaled to zero
        seen = shown[:, number]
        scale_visibility(buffer, take, seen, nodes[first], first, animation)
        if locators:  # each sucker a child of its link's joint, at the sucker
            joint_of = {int(b): first + j for j, b in enumerate(skeleton.bodies)}
            offsets = dict(zip(skeleton.bodies.tolist(), skeleton.offset.tolist(), strict=True))
            for parent, child in sucker_nodes(take, name, offsets):
                nodes.append(child)
                nodes[joint_of[parent]].setdefault("children", []).append(len(nodes) - 1)
        if progress is not None:
            progress(1)
    if locators:
        add_gltf_goals(take, buffer, nodes, animation)
    add_gltf_ground(take, buffer, nodes, meshes, materials, to_y_up_points)
    document: Document = {
        **document_head(header, roots),
        "nodes": nodes,
        "meshes": meshes,
        "skins": skins,
        "materials": materials,
        "textures": [{"sampler": 0, "source": i} for i in range(len(images))],
        "samplers": [{"magFilter": 9729, "minFilter": 9729}],
        "images": images,
        "animations": [animation],
        **buffer.fields(),
    }
    return document, tally.report()


def _mesh(buffer: GlbBuffer, mesh: SkinMesh, name: str, material: int) -> Mesh:
    source, uv, triangles = split_by_uv(mesh)
    if len(source) > MAX_SKIN_VERTICES:
        raise ValueError(
            f"creature {name}: {len(source)} skinned vertices, over glTF's 16-bit indices here;"
            " use fewer rings per link or sides"
        )
    joints = np.zeros((len(source), 4), np.uint16)
    joints[:, :2] = mesh.joints[source]
    weights = np.zeros((len(source), 4), np.float32)
    weights[:, 0] = mesh.weights[source, 0].astype(np.float32)
    weights[:, 1] = np.float32(1.0) - weights[:, 0]  # exact float32 sums
    attributes = {
        "POSITION": buffer.add(
            to_y_up_points(mesh.positions[source]).astype(np.float32), "VEC3", ARRAY_BUFFER
        ),
        "NORMAL": buffer.add(
            to_y_up_points(mesh.normals[source]).astype(np.float32), "VEC3", ARRAY_BUFFER
        ),
        "TEXCOORD_0": buffer.add((uv * [1, -1] + [0, 1]).astype(np.float32), "VEC2", ARRAY_BUFFER),
        "JOINTS_0": buffer.add(joints, "VEC4", ARRAY_BUFFER),
        "WEIGHTS_0": buffer.add(weights, "VEC4", ARRAY_BUFFER),
    }
    indices = buffer.add(triangles.reshape(-1).astype(np.uint16), "SCALAR", ELEMENT_ARRAY_BUFFER)
    return triangle_mesh(f"{name}/skin", attributes, indices, material)


def _channels(
    buffer: GlbBuffer,
    take: Take,
    creature: SkinnedCreature,
    first: int,
    animation: Animation,
    times: dict[bytes, int],
) -> None:
    """A rotation channel per joint and the root's translation channel, with their keys,
    added to `animation`."""
    samplers, channels = animation["samplers"], animation["channels"]
    seconds = take.times.astype(np.float32)
    interpolation: Interpolation = "LINEAR" if take.frames > 1 else "STEP"
    rotation = to_y_up_rotations(creature.animation.rotation).astype(np.float32)
    root = to_y_up_points(creature.translations_at(np.arange(take.frames))[:, 0])

    def sampler(
        keep: np.ndarray, values: np.ndarray, kind: AccessorType, node: int, path: TargetPath
    ) -> None:
        mask = keep.tobytes()
        if mask not in times:
            times[mask] = buffer.add(seconds[keep], "SCALAR")
        output = buffer.add(np.ascontiguousarray(values[keep]), kind)
        samplers.append({"input": times[mask], "output": output, "interpolation": interpolation})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})

    for j in range(len(creature.skeleton.names)):
        sampler(creature.rotation_keys[:, j], rotation[:, j], "VEC4", first + j, "rotation")
    sampler(creature.translation_keys, root.astype(np.float32), "VEC3", first, "translation")
