"""Stopping signals (Ctrl-C, SIGTERM, SIGHUP) taken where the work can stop cleanly.

Python's own Ctrl-C handler raises KeyboardInterrupt wherever the main thread is, and
some places cannot take it:

- inside a callback from C, such as llvmlite's while numba loads or compiles a kernel in
  a world's first frames, the exception is printed as ignored and the run goes on: a
  bake stopped as it started kept baking, and one crashed (SIGSEGV) calling a kernel
  left half loaded;
- inside pybind11's conversion of an argument it comes out as a TypeError ("incompatible
  function arguments"), so a bake stopped while its world was built failed with that;
- inside code that a C library runs with `PyRun_String`, CPython marks it unhandled and,
  at exit, kills its own process with SIGINT although the command handled it (exit -2
  where 130 was due).

So the command line installs `handle` for these signals (`ecs_tentacles.cli.command`).
Where the work is mostly such code, a world stepping its frames (`World.step`) or being
built (`ecs_tentacles.creatures.loading`), it runs inside `deferred()`: a signal there is
kept and raised by the next `check()`, at the next frame or creature, milliseconds
later; a second signal while one is kept is raised at once (the way out of a long
step). Elsewhere a signal raises at once, as Python's handler does, so a blocking wait
(a sleep, a subprocess, Ray) is cut short. Either way the stop is remembered until the
command reports it (`taken()`): one swallowed anyway is raised again by the next
`check()` (each frame, and before an output is committed: `ecs_tentacles.output.atomic`),
and a command that failed with another exception while a stop was remembered reports
the stop (`received()`). Without `handle` installed (the library on its own) nothing
is ever remembered and `check()` does nothing. Only the main thread takes signals, so
only its regions defer and only it raises.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds like Ctrl-C so partial outputs are removed."""


_received: BaseException | None = None  # the stop not yet reported
_kept = False  # `_received` arrived inside `deferred()` and waits for a `check()`
_depth = 0  # the main thread's nested `deferred()` regions
_MAIN = threading.main_thread()


def _stop_for(number: int) -> BaseException:
    if number == signal.SIGINT:
        return KeyboardInterrupt()
    return Terminated(signal.Signals(number).name)


def handle(number: int, frame: FrameType | None) -> None:
    """The signal handler: keep the stop inside `deferred()` (unless one is kept
    already), else raise it now; remember it until `taken()`."""
    global _received, _kept
    again = _kept
    _received = _stop_for(number)
    if _depth and not again:
        _kept = True
        return
    _kept = False
    raise _received


def check() -> None:
    """Raise the remembered stop, if there is one (main thread only): a kept one is
    due, and one raised before was swallowed somewhere if the work still goes on."""
    global _kept
    stop = _received
    if stop is None or threading.current_thread() is not _MAIN:
        return
    _kept = False
    raise type(stop)(*stop.args)


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """Inside: a stopping signal waits for the next `check()`; a stop kept when the
    region ends (without an exception) is raised then."""
    global _depth
    if threading.current_thread() is not _MAIN:
        yield
        return
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
    if _kept:
        check()


def received() -> BaseException | None:
    """The stop that arrived and was not yet reported, if any."""
    return _received


def taken() -> None:
    """The stop was reported (or a new command starts): nothing is remembered."""
    global _received, _kept
    _received, _kept = None, False


@contextlib.contextmanager
def stops_by_exception() -> Iterator[None]:
    """While inside, the stopping signals go to `handle` (main thread only: elsewhere
    signals are left alone); the handlers before are put back after."""
    try:
        previous = {number: signal.signal(number, handle) for number in SIGNALS}
    except ValueError:  # not the main thread
        previous = {}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
