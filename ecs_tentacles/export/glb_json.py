"""The widest a glb's JSON chunk can be, from how many of each item it holds.

    count = JsonCount()
    count.add("body", bodies)               # items by template (`TEMPLATES`)
    count.name("octo_t0_link3")             # every name, as written
    count.bound(binary_bytes)               # characters at most

Each template is a JSON item as the glTF writers (`export.gltf`, `export.skinned_gltf`)
make it, with every number at its widest: indices as wide as the largest count of any
item, byte lengths and offsets as wide as the binary chunk, floats at 24 characters
(the longest `repr` of a float); names are counted apart, exactly (`name`).
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Callable

from ecs_tentacles import __version__

F = -2.2250738585072014e-308  # a float as wide as `repr` writes one: 24 characters
F3, F4 = [F] * 3, [F] * 4
KIND = "k" * 16  # a locator's kind (`goal`, a plugin's points item), at most

# fmt: off
# (index, byte count) -> the widest form of an item; "" stands for its name
TEMPLATES: dict[str, Callable[[int, int], object]] = {
    "view": lambda i, b: {"buffer": 0, "byteLength": b, "byteOffset": b, "target": 34963},
    "vec3": lambda i, b: {"bufferView": i, "componentType": 5126, "count": b, "max": F3,
                          "min": F3, "type": "VEC3"},
    "scalar": lambda i, b: {"bufferView": i, "componentType": 5126, "count": b, "max": [F],
                            "min": [F], "type": "SCALAR"},
    "plain": lambda i, b: {"bufferView": i, "componentType": 5126, "count": b,
                           "type": "SCALAR"},
    "sampler": lambda i, b: {"input": i, "interpolation": "LINEAR", "output": i},
    "channel": lambda i, b: {"sampler": i, "target": {"node": i, "path": "translation"}},
    "body": lambda i, b: {"children": [], "mesh": i, "name": "", "rotation": F4,
                          "translation": F3},
    "joint": lambda i, b: {"children": [], "name": "", "rotation": F4, "translation": F3},
    "folder": lambda i, b: {"children": [], "name": ""},
    "skin_node": lambda i, b: {"mesh": i, "name": "", "skin": i},
    "sucker": lambda i, b: {"extras": {"ecs:locator": "sucker"}, "name": "", "translation": F3},
    "goal": lambda i, b: {"extras": {"ecs:locator": KIND, "ecs:radius": F}, "name": "",
                          "scale": F3, "translation": F3},
    "scale_key": lambda i, b: {"scale": [0.0, 0.0, 0.0]},  # a node hidden as it starts
    "child": lambda i, b: i,  # an index in a `children`, `joints` or `nodes` list
    "rigid_mesh": lambda i, b: {"name": "cylinder", "primitives": [{"attributes": {
        "NORMAL": i, "POSITION": i}, "indices": i, "material": i, "mode": 4}]},
    "skin_mesh": lambda i, b: {"name": "", "primitives": [{"attributes": dict.fromkeys(
        ("JOINTS_0", "NORMAL", "POSITION", "TEXCOORD_0", "WEIGHTS_0"), i), "indices": i,
        "material": i, "mode": 4}]},
    "colour": lambda i, b: {"name": "", "pbrMetallicRoughness": {"baseColorFactor": F4,
                            "metallicFactor": F, "roughnessFactor": F}},
    "textured": lambda i, b: {"name": "", "pbrMetallicRoughness": {"baseColorTexture": {
        "index": i}, "metallicFactor": F, "roughnessFactor": F}},
    "image": lambda i, b: {"bufferView": i, "mimeType": "image/png"},
    "texture": lambda i, b: {"sampler": 0, "source": i},
    "skin": lambda i, b: {"inverseBindMatrices": i, "joints": [], "name": "", "skeleton": i},
    "mesh_node": lambda i, b: {"mesh": i, "name": ""},
    "document": lambda i, b: {
        "accessors": [], "animations": [{"channels": [], "name": "", "samplers": []}],
        "asset": {"extras": {"fps": F, "scene": "", "scene_sha256": "0" * 64, "seed": -(2**63)},
                  "generator": f"ecs_tentacles {__version__}", "version": "2.0"},
        "bufferViews": [], "buffers": [{"byteLength": b}], "images": [], "materials": [],
        "meshes": [], "nodes": [], "samplers": [{"magFilter": 9729, "minFilter": 9729}],
        "scene": 0, "scenes": [{"name": "", "nodes": []}], "skins": [], "textures": []},
}
INDEXED = ("view", "vec3", "scalar", "plain", "sampler", "channel", "body", "joint", "folder",
           "skin_node", "sucker", "goal", "rigid_mesh", "skin_mesh", "colour", "textured",
           "image", "texture", "skin", "mesh_node")
# fmt: on


def _width(item: object) -> int:
    """Characters of `item` in the JSON, with the comma after it."""
    return len(json.dumps(item, separators=(",", ":"))) + 1


class JsonCount:
    """Items of a glb's JSON by template, and the characters of their names."""

    def __init__(self) -> None:
        self.items: Counter[str] = Counter()
        self.names = 0

    def add(self, template: str, count: int = 1) -> None:
        """`count` more items of `template` (a key of `TEMPLATES`)."""
        self.items[template] += count

    def name(self, text: str, count: int = 1) -> None:
        """`count` names `text` (escaped as JSON writes it; the quotes are the template's)."""
        self.names += count * (len(json.dumps(text)) - 2)

    def bound(self, binary_bytes: int) -> int:
        """Characters of the JSON at most, for a binary chunk of `binary_bytes`."""
        most = max((self.items[key] for key in INDEXED), default=0)
        index = 10 ** len(str(max(most, 1))) - 1
        byte = 10 ** len(str(max(binary_bytes, 1))) - 1
        widths = {key: _width(make(index, byte)) for key, make in TEMPLATES.items()}
        return self.names + sum(widths[key] * count for key, count in self.items.items())
