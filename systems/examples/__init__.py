"""Example plugins (not on by default): wander, flee, follow_leader, flock."""
