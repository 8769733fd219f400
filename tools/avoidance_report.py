"""Avoidance report: how much a crossing crowd touches with crowd avoidance and without.

    python tools/avoidance_report.py                       # 16 and 64 creatures, 20 s each
    python tools/avoidance_report.py --creatures 16 --seconds 10 --jobs 1
    python tools/avoidance_report.py --json                # one JSON row per run

Each run is `crowd_scene(N, seed)` (mirrored goals: the whole crowd crosses the middle)
headless, once as generated (avoidance on, the default) and once with the scene's
`avoidance.enabled` false. Per run: contacts a frame (pairs of creatures whose bodies are
within the level of detail's contact margin, the bounding spheres `world.lod` promotes
by, averaged over frames), contact frames (frames with at least one such pair), the
promotions the level of detail made (`world.lod.promotions`), the tiers at the end, and
progress (metres the mantles got closer to their goals, on average).
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.world import World


def run(creatures: int, avoid: bool, seconds: float, seed: int) -> dict[str, Any]:
    """One crossing crowd for `seconds`: contacts, promotions, tiers, progress."""
    scene = crowd_scene(creatures, seed=seed)
    if not avoid:
        scene["avoidance"] = {"enabled": False}
    world = World.from_scene(scene)
    try:
        proxies, margin = world.physics.proxies, world.lod.settings.contact_margin
        goals = world.resource(LocomotionStores).creatures.goal[:, :2].copy()
        start = world.transforms.pos[world.creatures.mantle_row, :2].copy()
        frames = round(seconds * world.settings.fps)
        pairs = touching = 0
        began = time.perf_counter()
        for _ in range(frames):
            world.step()
            pos, _, centre, radius = proxies.sense(world.transforms)
            near = int((proxies.pair_gaps(pos, centre, radius, margin)[2] < margin).sum())
            pairs += near
            touching += near > 0
        wall = time.perf_counter() - began
        end = world.transforms.pos[world.creatures.mantle_row, :2]
        progress = np.linalg.norm(start - goals, axis=1) - np.linalg.norm(end - goals, axis=1)
        return {
            "creatures": creatures,
            "avoidance": avoid,
            "seconds": seconds,
            "contacts_a_frame": pairs / frames,
            "contact_frames": touching,
            "frames": frames,
            "promotions": world.lod.promotions,
            "tiers": world.lod.counts(),
            "progress_m": float(progress.mean()),
            "wall_s": wall,
        }
    finally:
        world.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--creatures", type=int, nargs="+", default=[16, 64])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=2, help="runs at once (processes)")
    parser.add_argument("--json", action="store_true", help="one JSON row per run")
    args = parser.parse_args()
    cases = [(n, avoid, args.seconds, args.seed) for n in args.creatures for avoid in (True, False)]
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        rows = list(pool.map(run, *zip(*cases, strict=True)))
    if args.json:
        for row in rows:
            print(json.dumps(row))
        return
    print(f"crossing crowd (crowd_scene, seed {args.seed}), {args.seconds:g} s")
    print("creatures  avoidance  contacts/frame  contact frames  promotions  progress  tiers")
    for r in rows:
        tiers = "/".join(str(r["tiers"][k]) for k in ("full", "reduced", "kinematic"))
        print(
            f"{r['creatures']:>9}  {'on' if r['avoidance'] else 'off':>9}  "
            f"{r['contacts_a_frame']:>14.2f}  {r['contact_frames']:>7} / {r['frames']:<5}  "
            f"{r['promotions']:>10}  {r['progress_m']:>6.2f} m  {tiers}"
        )


if __name__ == "__main__":
    main()
