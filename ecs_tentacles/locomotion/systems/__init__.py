"""The locomotion feature's systems (`ecs_tentacles.locomotion`): goals,
tentacle_selection (stage decide), action_queue, motor_targets, suckers (stage act)."""
