"""The race mode's systems: `steering` (stage decide) and `referee` (stage output)."""
