"""Goal-directed locomotion: actions and their queues, poses, goals and parameters.

The systems in `locomotion.systems` (goals, tentacle_selection, action_queue,
motor_targets, suckers) do the per-frame work with these pieces.
"""
