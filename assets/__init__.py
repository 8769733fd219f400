"""Bundled data: scene files (`scenes/`) and the scene JSON Schema (`schema/`)."""
