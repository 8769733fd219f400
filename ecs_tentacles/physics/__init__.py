"""The MuJoCo backend: model building from entities, stepping and syncing."""
