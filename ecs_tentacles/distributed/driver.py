"""Run a bake's shards on Ray and merge them: `ray_bake(plan, out, ...)`.

With no address a local Ray starts (quiet: no dashboard, workers' logs kept out of
the terminal); with one, the bake joins that cluster; if this process already runs
Ray (a test, a notebook) it is used as is. Each shard is one task (`num_cpus=1`,
`max_retries`: a task whose worker dies, or that raises, is run again). Results
stream back with `ray.wait`; one progress bar counts simulated frames over every
shard (workers report to a small counter actor) and shards done. Each finished shard
is saved to the work folder (`ecs_tentacles.distributed.work`) at once.

When every shard is in, their contact spheres are checked (`spheres.meetings`):
shards whose creatures came within contact range are joined and baked again, until
none meet. Then the takes are merged into the local bake's take.

A shard that still fails after its retries fails the bake with one line naming it;
the other shards finish and stay in the work folder for `--resume`. Ctrl-C cancels
every running task (`ray.cancel`) and keeps the finished shards there too. `--resume`
uses a kept shard only when its signature is this user's (`work`); one that is not,
or does not read, is baked again with one line naming it and why. Without the key
(`secret`: a read-only home) no shard is kept or resumed, and one line says so.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import shutil
import signal
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
from tqdm import tqdm

from ecs_tentacles.distributed.merge import merge_takes
from ecs_tentacles.distributed.reaper import (
    Reaper,
    adopt_orphans,
    descendants,
    end_started_since,
)
from ecs_tentacles.distributed.registries import MeetingReaches
from ecs_tentacles.distributed.shards import (
    ShardPlan,
    default_tasks,
    entries,
    plan_shards,
    scene_plugins,
)
from ecs_tentacles.distributed.spheres import meetings
from ecs_tentacles.distributed.task import ShardResult, bake_shard
from ecs_tentacles.distributed.work import WorkFolder, remove_work, shard_key
from ecs_tentacles.export.bake import BakePlan
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.output.progress import status
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.take import Take


class ShardFailed(RuntimeError):
    """A shard failed after its retries; the message is one line naming it."""


@dataclass
class RayStats:
    """What a distributed bake did."""

    plan: ShardPlan | None = None
    baked: int = 0  # shard tasks run to completion
    resumed: int = 0  # shards loaded from the work folder
    rebaked: int = 0  # shards joined and baked again because their creatures met
    task_seconds: list[float] = field(default_factory=list)  # time inside each task
    task_cpu_seconds: list[float] = field(default_factory=list)  # CPU time of each task
    result_bytes: int = 0  # array bytes that came back from the workers
    workers: float = 0.0  # CPUs of the cluster


def start_ray(address: str | None, cpus: int | None) -> bool:
    """Join `address` or start a local Ray; False when this process already had Ray.

    A signal while Ray starts (Ctrl-C, SIGTERM: `ray.init` takes seconds) ends what it
    had started before the exception goes on (`_abandon`). `ray.init` installs its own
    SIGTERM handler first thing (`sys.exit(15)`: no line, exit 15); a SIGTERM it caught
    is handed to the handler that was there before it (the command line's: one line,
    exit 143), as after the start.
    """
    import ray

    if ray.is_initialized():
        return False
    ours = _signal_handlers()
    before = descendants()
    adopt_orphans(True)  # a start cut short may orphan agents: they must stay ours to end
    try:
        _init(address, cpus, ours)
    except SystemExit as stop:  # Ray's SIGTERM handler ran while Ray started
        _abandon(before, ours)
        handler = ours.get(signal.SIGTERM)
        if stop.code == signal.SIGTERM and callable(handler):
            handler(signal.SIGTERM, None)  # ours raises (the command line's Terminated)
        raise
    except BaseException:  # Ctrl-C, or SIGTERM before Ray's handler was in place
        _abandon(before, ours)
        raise
    finally:
        adopt_orphans(False)
    return True


def _init(address: str | None, cpus: int | None, ours: dict[int, _Handler]) -> None:
    """`ray.init`, quiet; a local Ray gets its watchdog; our signal handlers back."""
    import ray

    global _REAPER
    quiet = functools.partial(
        ray.init, include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR
    )
    try:
        with _empty_working_folder():
            if address:
                try:
                    quiet(address)
                except ConnectionError as error:
                    raise ConnectionError(f"{error}{_token_hint()}") from None
            else:
                quiet(num_cpus=cpus)
                session = ray.get_runtime_context().get_session_name()
                _REAPER = Reaper.start(session)  # a local Ray never outlives a killed bake
    finally:
        for number, handler in ours.items():  # Ray installs its own: SIGTERM must stay
            signal.signal(number, handler)  # ours (one line, exit 143, Ray shut down)


def _token_hint() -> str:
    """Why a cluster may have refused this bake: Ray (2.60) starts a head with token
    authentication when `~/.ray/auth_token` exists (a local Ray writes it), and then
    refuses a client that does not set RAY_AUTH_MODE=token."""
    if os.environ.get("RAY_AUTH_MODE") == "token":
        return ""
    if not (Path.home() / ".ray" / "auth_token").is_file():
        return ""
    return (
        "; if the cluster uses token authentication (a head started where ~/.ray/auth_token"
        " exists does), run the bake with RAY_AUTH_MODE=token"
    )


@contextlib.contextmanager
def _empty_working_folder() -> Iterator[None]:
    """Ray puts the driver's working folder on its workers' import path and starts a
    local node's processes in it: a `numpy.py` where the user runs `bake --ray` would
    run in every worker. So Ray starts from an empty folder of this bake's own (kept
    until `stop_ray`: the workers' working folder), and the working folder comes back."""
    global _EMPTY
    here = os.getcwd()
    _EMPTY = tempfile.mkdtemp(prefix="ecs_tentacles_ray_")
    os.chdir(_EMPTY)
    try:
        yield
    finally:
        os.chdir(here)


def _remove_empty_folder() -> None:
    global _EMPTY
    if _EMPTY is not None:
        shutil.rmtree(_EMPTY, ignore_errors=True)
        _EMPTY = None


def _abandon(before: set[tuple[int, float]], ours: dict[int, _Handler]) -> None:
    """A Ray start cut short: shut down what `ray.init` made of it, then end every
    process started since `before` that is still there (its node was perhaps not yet
    known to `ray.shutdown`). SIGTERM, SIGINT and SIGHUP are ignored meanwhile (seconds):
    the bake is stopping already, and a second one must not cut this short."""
    import ray

    global _REAPER
    for number in ours:
        signal.signal(number, signal.SIG_IGN)
    try:
        try:
            ray.shutdown()
        except Exception:  # half started: whatever it cannot shut down is ended below
            pass
        if _REAPER is not None:
            _REAPER.stop()
            _REAPER = None
        end_started_since(before)
        _remove_empty_folder()
    finally:
        for number, handler in ours.items():
            signal.signal(number, handler)


def stop_ray(started: bool) -> None:
    """Shut down the Ray `start_ray` started (nothing when it joined one already running)."""
    global _REAPER
    if not started:
        return
    import ray

    ray.shutdown()
    if _REAPER is not None:
        _REAPER.stop()
        _REAPER = None
    _remove_empty_folder()


# what `signal.getsignal` gives for a signal with a handler (`SIG_DFL`, `SIG_IGN` or ours)
_Handler = Callable[[int, FrameType | None], object] | int | signal.Handlers
_REAPER: Reaper | None = None
_EMPTY: str | None = None  # the folder Ray was started from (`_empty_working_folder`)


def _signal_handlers() -> dict[int, _Handler]:
    """This process's SIGTERM, SIGINT and SIGHUP handlers (none off the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    numbers = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)
    return {n: h for n in numbers if (h := signal.getsignal(n)) is not None}


def _run_shard(
    plan: BakePlan, members: list[int], key: str, counter: Any, options: WorldOptions
) -> ShardResult:
    """The Ray task: bake one shard, telling `counter` of progress (if there is one)."""
    on_steps = None if counter is None else (lambda n: counter.add.remote(n))
    return bake_shard(plan, members, key, options, on_steps=on_steps)


class _Counter:
    def __init__(self) -> None:
        self.steps = 0

    def add(self, n: int) -> None:
        self.steps += n

    def value(self) -> int:
        return self.steps


def ray_bake(
    plan: BakePlan,
    folder: Path,
    *,
    address: str | None = None,
    cpus: int | None = None,
    resume: bool = False,
    retries: int = 3,
    progress: bool = True,
    options: WorldOptions | None = None,
    note: Callable[[str], None] = lambda line: print(line, file=sys.stderr),
) -> tuple[Take, RayStats]:
    """Bake `plan` on Ray; finished shards go to `folder` (see the module docstring).
    `options`: the code each shard may import (`allow_systems`); a shard steps on one
    thread and builds its own creatures."""
    import ray

    options = options or WorldOptions()
    allow_systems = options.allow_systems
    started = start_ray(address, cpus)
    try:
        cpus_total = ray.cluster_resources().get("CPU", 1)  # type: ignore[no-untyped-call, unused-ignore]
        stats = RayStats(workers=float(cpus_total))
        plugins = scene_plugins(plan.scene, plan.folder, allow_systems=allow_systems)
        tasks = default_tasks(stats.workers)
        stats.plan = plan_shards(plan.scene, plan.seconds, tasks, plugins)
        note(f"ray: {stats.plan.describe()}")
        if not resume:
            remove_work(folder)
        work = WorkFolder.open(folder, resume=resume, note=note)
        shards = stats.plan.shards
        results = _run_all(plan, shards, work, retries, progress, options, stats)
        while True:
            met = _meetings(plan, results, plugins)
            if not met:
                break
            shards = _join(shards, met)
            for i, j, frame in met[:3]:
                names = [plan.scene["creatures"][k]["name"] for k in (i, j)]
                note(
                    f"ray: {names[0]} and {names[1]} came within contact range at"
                    f" {frame / plan.sim_fps:.2f} s: baking their shards again as one"
                )
            todo = [s for s in shards if tuple(s) not in results]
            stats.rebaked += len(todo)
            results.update(_run_all(plan, todo, work, retries, progress, options, stats))
            results = {tuple(s): results[tuple(s)] for s in shards}
        with status(f"ray bake: merging {len(results)} shards", progress=progress):
            take = merge_takes([(r.members, r.take) for r in results.values()])
        return take, stats
    finally:
        stop_ray(started)


def _run_all(
    plan: BakePlan,
    shards: list[list[int]],
    work: WorkFolder,
    retries: int,
    progress: bool,
    options: WorldOptions,
    stats: RayStats,
) -> dict[tuple[int, ...], ShardResult]:
    import ray

    results: dict[tuple[int, ...], ShardResult] = {}
    keys = {tuple(s): shard_key(plan, s, options.allow_systems) for s in shards}
    number = {tuple(s): i for i, s in enumerate(shards)}
    for shard in shards:
        label = _label(plan, number[tuple(shard)], shard)
        found = work.kept(keys[tuple(shard)], label)
        if found is not None:
            results[tuple(shard)] = found
            stats.resumed += 1
    task = ray.remote(num_cpus=1, max_retries=retries, retry_exceptions=True)(_run_shard)
    plan_ref = ray.put(plan)
    to_bake = [s for s in shards if tuple(s) not in results]
    failures: list[str] = []
    total = plan.steps * len(to_bake)
    with tqdm(
        total=total,
        unit="frame",
        desc="ray bake",
        disable=None if progress else True,
        file=sys.stderr,
        leave=False,
    ) as bar:
        # the tasks count their frames to an actor only for a bar that is shown: the
        # actor is a process of its own (its start and imports: about a CPU-second)
        counter = None if bar.disable is True else ray.remote(num_cpus=0)(_Counter).remote()
        pending = {
            task.remote(plan_ref, s, keys[tuple(s)], counter, options): tuple(s) for s in to_bake
        }
        bar.set_postfix_str(f"shards 0/{len(pending)}")
        done = 0
        try:
            while pending:
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
                for ref in ready:
                    key = pending.pop(ref)
                    label = _label(plan, number[key], list(key))
                    try:
                        result: ShardResult = ray.get(ref)
                    except Exception as error:  # the task's error after its retries
                        failures.append(f"{label} failed: {_one_line(error)}")
                        continue
                    work.keep(keys[key], result)
                    results[key] = result
                    stats.baked += 1
                    stats.task_seconds.append(result.seconds)
                    stats.task_cpu_seconds.append(result.cpu_seconds)
                    stats.result_bytes += _nbytes(result)
                    done += 1
                    bar.set_postfix_str(f"shards {done}/{done + len(pending)}")
                if counter is not None:
                    steps = ray.get(counter.value.remote())  # type: ignore[attr-defined]
                    bar.update(min(total, steps) - bar.n)
        except BaseException:  # Ctrl-C, SIGTERM: stop every running task
            for ref in pending:
                ray.cancel(ref, force=True)
            raise
    if failures:
        more = f" (and {len(failures) - 1} more)" if len(failures) > 1 else ""
        raise ShardFailed(f"{failures[0]}{more}; finished shards kept for --resume")
    return results


def _meetings(
    plan: BakePlan, results: dict[tuple[int, ...], ShardResult], plugins: Sequence[Plugin]
) -> list[tuple[int, int, int]]:
    n = len(plan.scene["creatures"])
    first = next(iter(results.values())).spheres
    spheres = np.zeros((len(first), n, 4))
    shard_of = np.zeros(n, dtype=np.int64)
    for k, result in enumerate(results.values()):
        spheres[:, result.members] = result.spheres
        shard_of[result.members] = k
    reach = np.zeros(n)
    for meeting in entries(plugins).get(MeetingReaches):
        extra = meeting(plan.scene)
        if extra is not None:
            reach += np.asarray(extra, dtype=np.float64)
    return meetings(spheres, shard_of, reach)


def _join(shards: list[list[int]], met: list[tuple[int, int, int]]) -> list[list[int]]:
    """Shards with every met pair's shards joined into one."""
    groups = [set(s) for s in shards]
    for i, j, _ in met:
        a = next(g for g in groups if i in g)
        b = next(g for g in groups if j in g)
        if a is not b:
            a |= b
            groups.remove(b)
    return sorted(sorted(g) for g in groups)


def _label(plan: BakePlan, number: int, members: list[int]) -> str:
    names = [plan.scene["creatures"][i]["name"] for i in members[:3]]
    more = f", +{len(members) - 3}" if len(members) > 3 else ""
    return f"shard {number} ({', '.join(names)}{more})"


def _one_line(error: BaseException) -> str:
    cause = getattr(error, "cause", None) or error
    text = f"{type(cause).__name__}: {cause}".strip()
    lines = [line for line in text.splitlines() if line.strip()]
    return lines[0][:300].rstrip(".") if lines else type(cause).__name__


def _nbytes(result: ShardResult) -> int:
    arrays = result.take.arrays()
    return int(sum(a.nbytes for a in arrays.values()) + result.spheres.nbytes)
