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
(a sleep, a subprocess, Ray) is cut short. Inside a region the work may block too (a
build reading a FIFO no one writes, a plugin waiting on a socket): while a stop is kept,
a watcher thread looks at the main thread (Linux: `/proc/self/task/ID/stat` and
`wchan`), and when it has slept in the kernel for `GRACE` seconds in anything but a
lock (a frame waiting for its physics threads is not blocked), it sends the signal
again, which raises at once as a second one would: the read is cut short. Without
`/proc` the stop waits for its check as before. Either way the stop is remembered until the
command reports it (`taken()`): one swallowed anyway is raised again by the next
`check()` (each frame, and before an output is committed: `ecs_tentacles.output.atomic`),
and a command that failed with another exception while a stop was remembered reports
the stop (`received()`). Without `handle` installed (the library on its own) nothing
is ever remembered and `check()` does nothing. Only the main thread takes signals, so
only its regions defer and only it raises.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Iterator
from types import FrameType

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
GRACE = 0.25  # seconds a kept stop waits while the main thread is blocked in the kernel
POLL = 0.05  # seconds between the watcher's looks at the main thread


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds like Ctrl-C so partial outputs are removed."""


_received: BaseException | None = None  # the stop not yet reported
_kept = False  # `_received` arrived inside `deferred()` and waits for a `check()`
_depth = 0  # the main thread's nested `deferred()` regions
_number = 0  # the signal `_received` came by
_wake = -1  # the write end of the watcher's pipe (-1: no watcher)
_MAIN = threading.main_thread()


def _stop_for(number: int) -> BaseException:
    if number == signal.SIGINT:
        return KeyboardInterrupt()
    return Terminated(signal.Signals(number).name)


def handle(number: int, frame: FrameType | None) -> None:
    """The signal handler: keep the stop inside `deferred()` (unless one is kept
    already), else raise it now; remember it until `taken()`."""
    global _received, _kept, _number
    again = _kept
    _received, _number = _stop_for(number), number
    if _depth and not again:
        _kept = True
        if _wake >= 0:  # the watcher looks at the main thread until the stop is checked
            with contextlib.suppress(OSError):
                os.write(_wake, b"k")
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
    """While inside, the stopping signals go to `handle` and a watcher thread cuts short
    a blocked read that keeps a stop (main thread only: elsewhere signals are left
    alone); the handlers before are put back after."""
    try:
        previous = {number: signal.signal(number, handle) for number in SIGNALS}
    except ValueError:  # not the main thread
        previous = {}
    try:
        with _watcher() if previous else contextlib.nullcontext():
            yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


@contextlib.contextmanager
def _watcher() -> Iterator[None]:
    """A thread that sleeps on a pipe until `handle` keeps a stop (one already running
    serves nested regions)."""
    global _wake
    if _wake >= 0:
        yield
        return
    wake, _wake = os.pipe()
    os.set_blocking(_wake, False)  # the handler never waits on a full pipe
    thread = threading.Thread(target=_watch, args=(wake,), name="stops-watcher", daemon=True)
    thread.start()
    try:
        yield
    finally:
        write, _wake = _wake, -1  # the handler writes no more (it runs on this thread)
        os.write(write, b"q")
        thread.join()
        os.close(write)
        os.close(wake)


def _watch(wake: int) -> None:
    """For each kept stop: while it is kept, send its signal again once the main thread
    has been blocked (`blocked`) for `GRACE` seconds."""
    while os.read(wake, 1) == b"k":
        asleep = 0.0
        while _kept and _wake >= 0:
            time.sleep(POLL)
            asleep = asleep + POLL if blocked(_MAIN.native_id) else 0.0
            if asleep >= GRACE and _kept and signal.getsignal(_number) is handle:
                assert _MAIN.ident is not None
                signal.pthread_kill(_MAIN.ident, _number)  # raises at once: `again`
                break


def blocked(thread: int | None) -> bool:
    """Whether the thread of native id `thread` sleeps in the kernel in anything but a
    lock (a read, an open, a select, a sleep; not a futex, which the GIL and the locks
    of `threading` wait in). False where `/proc` does not say; True where the kernel
    hides the wait's name (`wchan`)."""
    try:
        with open(f"/proc/self/task/{thread}/stat", "rb") as status:
            state = status.read().rpartition(b")")[2].split()[0]
    except (OSError, IndexError):
        return False
    if state != b"S":  # running (R), or in a wait no signal ends (D)
        return False
    try:
        with open(f"/proc/self/task/{thread}/wchan", "rb") as waiting:
            return b"futex" not in waiting.read()
    except OSError:
        return True
