"""Built-in systems, one per file; installed as `ecs_tentacles.systems`.

Each system belongs to a plugin (`ecs_tentacles.plugins`) and runs in a public stage
(`ecs_tentacles.system.STAGES`); `world.schedule.table()` (or `ecs-tentacles systems
SCENE`) shows the resolved frame with what each system reads and writes:

decide   goals               mantle inside its current goal's radius -> next goal (locomotion)
         tentacle_selection  who drives, push or pull (cyclic or coordinated gait) (locomotion)
act      action_queue        action timers advance; finished actions give way (locomotion)
         motor_targets       action poses + travelling waves -> joint targets (locomotion)
         suckers             attach on command; release on command, stretch or reach (suckers)
physics  physics             targets, gains, suckers, contact proxies -> mj_step (core)
sync     physics_sync        MuJoCo body poses -> Transform store (core)
         physics_health      blow-ups found per creature and recovered (core)

The core systems (`physics/`) are declared by the physics package
(`ecs_tentacles.physics.frame_systems.physics_systems`) and run in every world.
animate  threats             path threats follow their keyframes (threats)
         emotion             threats near -> fear -> fur lift and random (fur)
         rig                 fur guides posed from mantle poses and controls (fur)
output   record              the frame into a take (record; `bake`)
         render              poses to the sandbox renderer (render; `play`)

`examples/` holds example plugins that are not on by default (wander, flee,
follow_leader, flock); a scene turns them on by name under `plugins`.
"""
