"""The scene reference page, written when the site is built (mkdocs-gen-files): every key
a scene may hold, from the schema files and the plugins as they are now (scene_keys.py)."""

import importlib.util
from pathlib import Path

import mkdocs_gen_files

spec = importlib.util.spec_from_file_location(
    "scene_keys", Path(__file__).with_name("scene_keys.py")
)
assert spec is not None and spec.loader is not None
scene_keys = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scene_keys)

with mkdocs_gen_files.open("scenes/reference.md", "w") as reference:
    reference.write(scene_keys.page())
