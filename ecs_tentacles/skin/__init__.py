"""Skinned creatures: one watertight mesh per creature on a joint skeleton.

Modules: `skeleton` (joints, bind pose and animation from a take), `mesh` (the
creature mesh with skin weights and UVs), `keys` (key reduction for editable curves).
The CPU reference of linear blend skinning the exporters are checked against is the
tests' (`tests/skin/cpu_skinning.py`).
"""
