"""Skinned creatures: one watertight mesh per creature on a joint skeleton.

Modules: `skeleton` (joints, bind pose and animation from a take), `mesh` (the
creature mesh with skin weights and UVs), `skinning` (linear blend skinning, the CPU
reference), `keys` (key reduction for editable curves).
"""
