"""`bake --ray [ADDRESS]` and `bake --wedge PATH=VALUES`: the distributed side of `bake`.

Ray is imported only here, and only when one of these options is given.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Protocol

from ecs_tentacles.cli.arguments import bounded_int
from ecs_tentacles.cli.world_options import world_options
from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.output.atomic import claim
from ecs_tentacles.take import Take


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The distributed options of `bake`."""
    parser.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        metavar="ADDRESS",
        help="bake on Ray (pip install 'ecs-tentacles[ray]'): join the cluster at ADDRESS,"
        " or start a local one",
    )
    parser.add_argument(
        "--cpus",
        type=bounded_int(1, 4096),
        default=None,
        help="CPUs of a local Ray (default: all of them)",
    )
    parser.add_argument(
        "--retries",
        type=bounded_int(0, 100),
        default=3,
        help="runs of a failed Ray task after the first",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="reuse the shards an interrupted --ray bake finished (kept in .OUT.work/)",
    )
    parser.add_argument(
        "--wedge",
        action="append",
        default=[],
        metavar="PATH=VALUES",
        help="bake every combination: PATH a scene JSON path, VALUES A..B or a,b,c;"
        " --out names each output with {name}",
    )


def ray_problem(args: argparse.Namespace) -> str | None:
    """The one-line problem with the distributed options (Ray missing...), else None."""
    import importlib.util

    if args.resume and (args.ray is None or args.wedge):
        return "argument --resume: only for a --ray bake without --wedge"
    if args.ray is not None and importlib.util.find_spec("ray") is None:
        return "argument --ray: needs Ray: pip install 'ecs-tentacles[ray]'"
    return None


def bake_on_ray(args: argparse.Namespace, plan: BakePlan) -> Take:
    """Bake `plan` in shards on Ray, keeping finished shards beside `args.out`."""
    from ecs_tentacles.distributed.driver import ray_bake
    from ecs_tentacles.distributed.work import remove_work, work_folder

    folder = work_folder(args.out)
    try:
        take, stats = ray_bake(
            plan,
            folder,
            address=args.ray or None,
            cpus=args.cpus,
            resume=args.resume,
            retries=args.retries,
            progress=not args.quiet,
            options=world_options(args),
        )
    except BaseException:
        kept = len(list(folder.glob("*.npz"))) if folder.is_dir() else 0
        if kept:
            print(f"note: {kept} finished shard(s) kept in {folder} for --resume", file=sys.stderr)
        else:
            remove_work(folder)
        raise
    args.after_write = lambda: remove_work(folder)
    print(
        f"ray: {stats.baked} shard(s) baked, {stats.resumed} resumed, {stats.rebaked} re-baked"
        f" together on {stats.workers:g} CPU(s)",
        file=sys.stderr,
    )
    return take


def _bake_variant(plan: BakePlan, options: WorldOptions) -> Take:
    return bake(plan, options.but(threads=1), progress=False)


class Saves(Protocol):
    """How a variant's take is written (`cli.bake.save`)."""

    def __call__(self, take: Take, path: Path, *, progress: bool) -> object: ...


def run_wedge(args: argparse.Namespace, plan: BakePlan, save: Saves) -> int:
    """Bake every variant (on Ray with --ray, else here), write each output and wedge.json."""
    from ecs_tentacles.distributed.wedge import (
        output_for,
        outputs_problem,
        parse_parameter,
        variants,
        write_index,
    )

    parameters = [parse_parameter(text) for text in args.wedge]
    folder = Path(plan.folder) if plan.folder else None
    allow = args.allow_systems
    every = variants(plan.scene, parameters, plan.source, allow_systems=allow, scene_dir=folder)
    pattern: Path = args.out
    if len(every) > 1 and "{name}" not in pattern.name:
        print("error: argument --out: a wedge needs {name} in the file name", file=sys.stderr)
        return 2
    problem = outputs_problem(pattern, every)
    if problem:
        print(f"error: {problem}", file=sys.stderr)
        return 2
    index = pattern.parent / "wedge.json"
    for out in [output_for(pattern, v.name) for v in every] + [index]:
        claim(out)  # what each file is now: another run writing one meanwhile wins it
    if index.exists():
        print(f"note: {index} exists: this wedge replaces it", file=sys.stderr)
    options = world_options(args).but(scene_dir=plan.folder, lod=None, focus=None)
    plans = [  # (the variants' scenes have the options' lod and focus in: `plan.scene`'s)
        BakePlan.make(v.scene, options, seconds=plan.seconds, fps=plan.fps) for v in every
    ]
    for variant, variant_plan in zip(every, plans, strict=True):
        problem = variant_plan.size_problem()  # a variant may grow what a take holds
        if problem:
            print(f"error: argument --wedge: variant {variant.name}: {problem}", file=sys.stderr)
            return 2
        problem = variant_plan.glb_problem(output_for(pattern, variant.name), None, None)
        if problem:  # each variant's glb (rigid, as `save` writes it) fits in 4 GiB
            print(f"error: argument --wedge: variant {variant.name}: {problem}", file=sys.stderr)
            return 2
    print(f"wedge: {len(every)} variants -> {pattern.parent}", file=sys.stderr, flush=True)
    takes = _wedge_takes(args, plans)
    rows = []
    for variant, take in zip(every, takes, strict=True):
        out = output_for(pattern, variant.name)
        save(take, out, progress=not args.quiet)
        rows.append({"name": variant.name, "file": str(out), "parameters": variant.values})
    base = {
        "scene": plan.source,
        "seconds": plan.seconds,
        "fps": plan.fps,
        "parameters": [p.text for p in parameters],
    }
    index = write_index(pattern, base, rows)
    print(f"{index}: {len(rows)} outputs")
    return 0


def _wedge_takes(args: argparse.Namespace, plans: list[BakePlan]) -> list[Take]:
    from tqdm import tqdm

    bar = tqdm(
        total=len(plans), unit="bake", desc="wedge", disable=None if not args.quiet else True
    )
    with bar:
        if args.ray is None:
            out = []
            for p in plans:
                out.append(bake(p, world_options(args), progress=False))
                bar.update(1)
            return out
        import ray

        from ecs_tentacles.distributed.driver import start_ray, stop_ray

        started = start_ray(args.ray or None, args.cpus)
        try:
            task = ray.remote(num_cpus=1, max_retries=args.retries, retry_exceptions=True)(
                _bake_variant
            )
            refs = [task.remote(p, world_options(args)) for p in plans]
            pending = set(refs)
            try:
                while pending:
                    ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
                    pending -= set(ready)
                    bar.update(len(ready))
                return [ray.get(ref) for ref in refs]
            except BaseException:
                for ref in pending:
                    ray.cancel(ref, force=True)
                raise
        finally:
            stop_ray(started)
