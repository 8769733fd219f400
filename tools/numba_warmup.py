"""Compile the package's numba kernels ahead of a test run, once, so that every
pytest-xdist worker loads them from numba's on-disk cache instead of compiling them
itself (each worker of a fresh clone otherwise compiles the same kernels again).

Reads `tests/kernel_signatures.json`: `{"module:qualname": ["(argument types)", ...]}`,
the signatures the test suite calls each `cache=True` kernel with. Writes numba's cache
files (`__pycache__/*.nbi|*.nbc` beside each kernel's source, or under
`NUMBA_CACHE_DIR`): the same files, keyed by the same source stamp and signature, that a
worker looks up when it first calls the kernel.

    python tools/numba_warmup.py compile --claims DIR   # run one per core, same DIR
    python tools/numba_warmup.py record                 # the list, after a test run

`compile` processes sharing a claims folder split the kernels between them: each takes
the next kernel no other has claimed (an exclusive file create), the slowest to compile
(the parallel fur kernels) first, so they end together. A kernel's signatures stay in one
process: two processes saving to one kernel's index at once could lose an entry. A
signature that no longer compiles (its kernel's arguments changed since `record`) is
counted as stale and left to the worker that meets it; `record` writes the list anew.
`record` reads the caches the current sources' kernels left (run the suite first) and
writes the list through a temporary file and a rename.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "ecs_tentacles"
LIST = ROOT / "tests" / "kernel_signatures.json"


def kernel_modules() -> list[str]:
    """The package's modules that define cached numba kernels (by their source text:
    nothing else is imported)."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        if "njit" in text and "cache=True" in text:
            found.append(".".join(path.relative_to(ROOT).with_suffix("").parts))
    return found


def dispatchers(module_name: str) -> Iterator[tuple[str, Any]]:
    """`(module:qualname, dispatcher)` of each cached numba kernel `module_name` binds."""
    from numba.core.dispatcher import Dispatcher

    module = importlib.import_module(module_name)
    seen: set[int] = set()
    for value in vars(module).values():
        if not isinstance(value, Dispatcher) or id(value) in seen:
            continue
        seen.add(id(value))
        kernel: Any = value  # numba's cache and options are not in its type stubs
        cached = hasattr(kernel._cache, "_cache_file")  # cache=True
        if cached and kernel.targetoptions.get("inline") != "always":  # inlined: no cache
            yield f"{module_name}:{kernel.py_func.__qualname__}", kernel


def parse(signature: str) -> tuple[Any, ...]:
    """A signature as `record` wrote it (the repr of numba's argument types), as types;
    numba's own signature strings are read the same way (`numba.core.sigutils`)."""
    from numba.core import types

    parsed = eval(signature, {"__builtins__": {}}, vars(types))  # our own list
    return tuple(parsed)


def cached_signatures(dispatcher: Any) -> list[str]:
    """The signatures `dispatcher`'s on-disk cache holds for its current source (stale
    entries, from an edited source, are not read), those that read back exactly."""
    overloads = dispatcher._cache._cache_file._load_index()
    out = []
    for key in overloads:
        text = repr(tuple(key[0]))
        try:
            if parse(text) == tuple(key[0]):
                out.append(text)
        except Exception:  # a type whose repr does not read back (a literal): left out
            continue
    return sorted(set(out))


def record(path: Path) -> int:
    """Write the list of every kernel's cached signatures to `path`; how many."""
    listed: dict[str, list[str]] = {}
    for module_name in kernel_modules():
        for name, dispatcher in dispatchers(module_name):
            signatures = cached_signatures(dispatcher)
            if signatures:
                listed[name] = signatures
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(listed, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    os.replace(tmp, path)
    return sum(map(len, listed.values()))


def _claim(claims: Path, name: str) -> bool:
    """True once, for the first process to claim kernel `name` in folder `claims`."""
    try:
        os.close(os.open(claims / name.replace(":", "."), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    return True


def _order(listed: dict[str, list[str]], found: dict[str, Any]) -> list[str]:
    """Kernels slowest to compile first: parallel ones, then by their signatures."""

    def cost(name: str) -> tuple[bool, int, str]:
        parallel = name in found and bool(found[name].targetoptions.get("parallel"))
        return (not parallel, -len(listed[name]), name)

    return sorted(listed, key=cost)


def compile_listed(listed: dict[str, list[str]], claims: Path) -> tuple[int, int]:
    """Compile the kernels of `listed` this process claims in `claims`, those not in the
    cache already; `(signatures compiled or found cached, signatures stale)`."""
    found: dict[str, Any] = {}
    for module_name in sorted({name.split(":")[0] for name in listed}):
        try:
            found.update(dispatchers(module_name))
        except ImportError:  # a module moved since `record`: its kernels count as stale
            continue
    done = stale = 0
    for name in _order(listed, found):
        if not _claim(claims, name):
            continue
        if name not in found:
            stale += len(listed[name])
            continue
        kernel = found[name]
        cached = kernel._cache._cache_file._load_index()
        for signature in listed[name]:
            try:
                args = parse(signature)
                if kernel._cache._index_key(args, kernel.targetctx.codegen()) not in cached:
                    kernel.compile(args)  # compiled and saved (a worker meets it cached)
                done += 1
            except Exception:  # the kernel's arguments changed since `record`
                stale += 1
    return done, stale


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("compile", help="compile the listed kernels this process claims")
    run.add_argument("--claims", type=Path, required=True, help="a folder shared by the processes")
    run.add_argument("--list", type=Path, default=LIST)
    rec = sub.add_parser("record", help="write the list from the caches a test run left")
    rec.add_argument("--list", type=Path, default=LIST)
    args = parser.parse_args(argv)
    if args.command == "record":
        print(f"{record(args.list)} signatures listed in {args.list}")
        return 0
    try:
        listed = json.loads(args.list.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        print(f"error: {args.list}: {error}", file=sys.stderr)
        return 2
    start = time.perf_counter()
    done, stale = compile_listed(listed, args.claims)
    print(f"{done} compiled or cached, {stale} stale, {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
