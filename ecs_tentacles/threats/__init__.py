"""Threats: marked threats on keyframed paths, and creatures marked as threats.

- `data`: the store and `ThreatData` resource, scene building and checks;
- `plugin`: the `threats` plugin (scene keys in `threats.schema.json`, its render
  markers); its system is `ecs_tentacles.threats.systems.threats`.
"""
