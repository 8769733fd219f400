"""Armatures, skinned meshes and materials (bpy): what is made once per body plan and
once per creature.

Per body plan (`motion.Plan`): one Armature datablock (a bone per body, in its rest
pose) and one Mesh datablock (the exporters' skinned mesh, `ecs_tentacles.skin.mesh`,
with a vertex group per bone), shared by every creature of the plan. Per creature: an
armature object on the plan's armature, a mesh object on the plan's mesh (parented to
it, deformed by it), and a material of the creature's sandbox colour
(`ecs_tentacles.skin.colours`), linked to the object, since the mesh is shared.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

from .motion import Plan, rest_offsets
from .shared import module

ROUGHNESS = 0.6  # as the USD and glTF materials (ecs_tentacles.export.materials)


@dataclass(frozen=True)
class _Tentacle:
    """`ecs_tentacles.skin.skeleton.TentacleLayout`'s fields the mesh reads."""

    angle: float
    lengths: np.ndarray
    radii: np.ndarray
    joints: np.ndarray


@dataclass(frozen=True)
class _Layout:
    """`ecs_tentacles.skin.skeleton.SkinLayout`'s fields the mesh reads."""

    name: str
    mantle_radius: float
    mantle_height: float
    tentacles: list[_Tentacle]


@dataclass(frozen=True)
class _Rest:
    """What `creature_mesh` reads of a skeleton: its layout and the mantle's bind
    matrix (here the identity: the mesh is made in the armature's frame)."""

    layout: _Layout
    bind: np.ndarray


def plan_armature(
    name: str, plan: Plan, collection: bpy.types.Collection
) -> tuple[bpy.types.Armature, np.ndarray]:
    """The plan's Armature datablock (bones in the construction pose; made through a
    temporary object in edit mode) and each bone's rest rotation offset from its joint
    (`motion.rest_offsets`)."""
    armature = bpy.data.armatures.new(name)
    holder = bpy.data.objects.new(name, armature)
    collection.objects.link(holder)
    layer = bpy.context.view_layer
    active = layer.objects.active
    layer.objects.active = holder
    try:
        bpy.ops.object.mode_set(mode="EDIT")
        bones: list[object] = []
        for j, bone_name in enumerate(plan.names):
            bone = armature.edit_bones.new(bone_name)
            bone.head = plan.heads[j].tolist()
            bone.tail = plan.tails[j].tolist()
            bone.roll = 0.0
            if plan.parents[j] >= 0:
                bone.parent = bones[plan.parents[j]]
            bones.append(bone)
        bpy.ops.object.mode_set(mode="OBJECT")
    finally:
        layer.objects.active = active
        bpy.data.objects.remove(holder)
    rotations = np.array([list(armature.bones[n].matrix_local.to_quaternion()) for n in plan.names])
    return armature, rest_offsets(plan, rotations)


def plan_mesh(name: str, plan: Plan) -> bpy.types.Mesh:
    """The plan's skinned Mesh datablock in the armature's frame: the exporters' mesh
    (`ecs_tentacles.skin.mesh.creature_mesh`), smooth, with UVs and a vertex group per
    bone; one material slot (each creature's object fills it)."""
    skin_mesh = module("skin_mesh")
    count = len(plan.tentacles)
    tentacles, first = [], 1
    for k, (lengths, radii) in enumerate(plan.tentacles):
        joints = np.arange(first, first + len(lengths))
        tentacles.append(
            _Tentacle(2.0 * np.pi * k / count, np.array(lengths), np.array(radii), joints)
        )
        first += len(lengths)
    layout = _Layout(name, plan.mantle_radius, plan.mantle_height, tentacles)
    made = skin_mesh.creature_mesh(_Rest(layout, np.eye(4)[None]))
    mesh = bpy.data.meshes.new(name)
    faces = made.faces.astype(np.int32)
    mesh.vertices.add(len(made.positions))
    mesh.vertices.foreach_set("co", made.positions.astype(np.float32).ravel())
    mesh.loops.add(faces.size)
    mesh.loops.foreach_set("vertex_index", faces.ravel())
    mesh.polygons.add(len(faces))
    mesh.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
    mesh.update()
    mesh.uv_layers.new(name="UVMap").uv.foreach_set("vector", made.uv.astype(np.float32).ravel())
    mesh.shade_smooth()
    mesh.materials.append(None)
    holder = bpy.data.objects.new(name, mesh)  # vertex groups are made through an object;
    try:  # their names and weights live in the mesh
        for j, bone_name in enumerate(plan.names):
            group = holder.vertex_groups.new(name=bone_name)
            for slot in range(2):
                on = (made.joints[:, slot] == j) & (made.weights[:, slot] > 0)
                weights = made.weights[on, slot]
                for weight in np.unique(weights).tolist():
                    group.add(np.flatnonzero(on)[weights == weight].tolist(), weight, "REPLACE")
    finally:
        bpy.data.objects.remove(holder)
    return mesh


def material(name: str, header: dict[str, object], index: int) -> bpy.types.Material:
    """Creature `index`'s material: its sandbox colour (the natural palette, as the
    exporters choose it) as the base colour (linear) and the viewport colour."""
    colours = module("skin_colours")
    srgb = colours.creature_colour(colours.look_in_take(header, index))
    linear = [*colours.to_linear(srgb).tolist(), 1.0]
    made = bpy.data.materials.new(name)
    made.diffuse_color = linear
    made.roughness = ROUGHNESS
    made.metallic = 0.0
    shader = next(n for n in made.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    shader.inputs["Base Color"].default_value = linear
    shader.inputs["Roughness"].default_value = ROUGHNESS
    shader.inputs["Metallic"].default_value = 0.0
    return made


def creature_objects(
    name: str,
    armature: bpy.types.Armature,
    mesh: bpy.types.Mesh,
    made_material: bpy.types.Material,
    collection: bpy.types.Collection,
) -> tuple[bpy.types.Object, bpy.types.Object]:
    """Creature `name`'s armature object (`<name>_skeleton`, on the shared armature) and
    skinned mesh object (`<name>_skin`, on the shared mesh, its child, deformed by it,
    its material linked to the object)."""
    skeleton = bpy.data.objects.new(f"{name}_skeleton", armature)
    skeleton.rotation_mode = "XYZ"
    skin = bpy.data.objects.new(f"{name}_skin", mesh)
    skin.parent = skeleton
    deform = skin.modifiers.new("skeleton", "ARMATURE")
    deform.object = skeleton
    collection.objects.link(skeleton)
    collection.objects.link(skin)
    slot = skin.material_slots[0]
    slot.link = "OBJECT"
    slot.material = made_material
    return skeleton, skin
