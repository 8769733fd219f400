"""The glTF 2.0 JSON the glTF writers make, as TypedDicts (only the fields they write).

`export.glb` (buffer views, accessors, the container), `export.gltf` (rigid bodies),
`export.skinned_gltf` (skins), `export.ground` and `export.materials` build a `Document`
of these; mypy checks each key and value against the glTF 2.0 specification's names
(https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html). Types only: reads and
writes nothing, costs nothing at run time (the objects stay plain dicts for `json`).
"""

from __future__ import annotations

from typing import Literal, TypedDict

AccessorType = Literal["SCALAR", "VEC2", "VEC3", "VEC4", "MAT4"]
Interpolation = Literal["LINEAR", "STEP"]
TargetPath = Literal["translation", "rotation", "scale"]


class Buffer(TypedDict):
    byteLength: int


class BufferView(TypedDict, total=False):
    buffer: int
    byteOffset: int
    byteLength: int
    target: int  # ARRAY_BUFFER or ELEMENT_ARRAY_BUFFER


class Accessor(TypedDict, total=False):
    bufferView: int
    byteOffset: int
    componentType: int  # FLOAT, UNSIGNED_SHORT or UNSIGNED_INT
    count: int
    type: AccessorType
    min: list[float]
    max: list[float]


class Primitive(TypedDict):
    attributes: dict[str, int]  # POSITION, NORMAL, ... -> accessor
    indices: int
    material: int
    mode: int  # 4: triangles


class Mesh(TypedDict):
    name: str
    primitives: list[Primitive]


class TextureInfo(TypedDict):
    index: int


class PbrMetallicRoughness(TypedDict, total=False):
    baseColorFactor: list[float]  # linear rgba
    baseColorTexture: TextureInfo
    metallicFactor: float
    roughnessFactor: float


class Material(TypedDict):
    name: str
    pbrMetallicRoughness: PbrMetallicRoughness


class Image(TypedDict):
    bufferView: int
    mimeType: str


class Texture(TypedDict):
    sampler: int
    source: int


class TextureSampler(TypedDict):
    magFilter: int
    minFilter: int


class NodeFields(TypedDict, total=False):
    """A node's fields but its name."""

    children: list[int]
    mesh: int
    skin: int
    translation: list[float]
    rotation: list[float]  # x, y, z, w
    scale: list[float]
    extras: dict[str, str | float]  # a locator's kind (`ecs:locator`) and radius


class Node(NodeFields, total=False):
    name: str


class Skin(TypedDict):
    name: str
    joints: list[int]
    skeleton: int
    inverseBindMatrices: int


class AnimationSampler(TypedDict):
    input: int
    output: int
    interpolation: Interpolation


class ChannelTarget(TypedDict):
    node: int
    path: TargetPath


class Channel(TypedDict):
    sampler: int
    target: ChannelTarget


class Animation(TypedDict, total=False):
    name: str
    samplers: list[AnimationSampler]
    channels: list[Channel]


class Asset(TypedDict):
    version: str
    generator: str
    extras: dict[str, object]  # the take's scene, scene_sha256, seed and fps


class Scene(TypedDict):
    name: str
    nodes: list[int]


class Document(TypedDict, total=False):
    """A glTF document as the writers make it (and `glb.read_glb` returns it)."""

    asset: Asset
    scene: int
    scenes: list[Scene]
    nodes: list[Node]
    meshes: list[Mesh]
    skins: list[Skin]
    materials: list[Material]
    textures: list[Texture]
    samplers: list[TextureSampler]
    images: list[Image]
    animations: list[Animation]
    buffers: list[Buffer]
    bufferViews: list[BufferView]
    accessors: list[Accessor]
