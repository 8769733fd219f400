"""Ctrl-C and SIGTERM stop a command promptly, in one line, wherever they land.

Real processes: each bake runs a plugin that, at a moment of its choosing, sends its own
process a signal from inside code Python's own handler cannot raise in (`ecs_tentacles.
stops`): a C callback (ctypes; numba's loader calls back like this in a world's first
frames), pybind11 converting an argument (MuJoCo's), and C running Python source
(`PyRun_String`). Before, the first went on baking for the whole ten minutes, the second
failed with a TypeError, the third ended killed by SIGINT (-2) instead of exit 130.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from ecs_tentacles import stops

STOPPER = """
import ctypes, os, signal

import mujoco
import numpy as np

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.system import System

WAY, WHEN, SIGNAL = "{way}", "{when}", signal.{signal}


def stop_now():
    os.kill(os.getpid(), SIGNAL)
    total = 0
    for i in range(1000):  # Python runs the handler at one of these bytecodes: in here
        total += i


class Converted:
    def __array__(self, dtype=None, copy=None):
        stop_now()
        return np.ones(3)


def inside_c():
    if WAY == "a C callback":
        ctypes.CFUNCTYPE(None)(stop_now)()
    elif WAY == "an argument conversion":
        mujoco.mju_norm3(Converted())
    else:  # C running Python source
        source = b"import os, signal\\nos.kill(os.getpid(), signal.%s)\\nt = sum(range(1000))"
        run = ctypes.pythonapi.PyRun_String
        run.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.py_object, ctypes.py_object]
        run.restype = ctypes.py_object
        space = {{}}
        run(source % SIGNAL.name.encode(), 257, space, space)  # 257: Py_file_input


class StopInsideC(System):
    name = "stop_inside_c"
    stage = "act"

    def process(self, world, dt):
        if WHEN == "stepping" and world.frame == 3:
            inside_c()


class Stopper(Plugin):
    name = "stopper"

    def build_creature(self, world, creature, spec):
        if WHEN == "building":
            inside_c()

    def systems(self):
        return [StopInsideC()]
"""

LINES = {
    "SIGINT": (130, "error: interrupted (Ctrl-C); partial outputs removed"),
    "SIGTERM": (143, "error: stopped by SIGTERM; partial outputs removed"),
}


def _bake(folder: Path, way: str, when: str, stop: str) -> subprocess.CompletedProcess[str]:
    (folder / "stopper.py").write_text(STOPPER.format(way=way, when=when, signal=stop))
    creature = {"name": "octo", "tentacles": {"count": 3, "links": 2}}
    scene = {"version": 1, "plugins": {"stopper": {"from": "stopper.py:Stopper"}}}
    (folder / "scene.json").write_text(json.dumps({**scene, "creatures": [creature]}))
    argv = ["bake", "scene.json", "--seconds", "3600", "--out", "take.npz", "--allow-systems"]
    return subprocess.run(  # an hour of simulation: a lost stop cannot end in time
        [sys.executable, "-m", "ecs_tentacles", *argv, "--quiet"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=90,
    )


def _said(done: subprocess.CompletedProcess[str]) -> list[str]:
    """What the bake said after its opening `bake: scene -> out: ...` line."""
    lines = done.stderr.splitlines()
    return lines[1:] if lines and lines[0].startswith("bake: ") else lines


@pytest.mark.parametrize("way", ["a C callback", "an argument conversion", "C running source"])
@pytest.mark.parametrize("when", ["stepping", "building"])
def test_ctrl_c_inside_c_code_stops_the_bake_in_one_line(
    tmp_path: Path, way: str, when: str
) -> None:
    done = _bake(tmp_path, way, when, "SIGINT")
    code, line = LINES["SIGINT"]
    assert (done.returncode, _said(done)) == (code, [line]), done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.json", "stopper.py"]


def test_sigterm_inside_a_c_callback_stops_the_bake_in_one_line(tmp_path: Path) -> None:
    done = _bake(tmp_path, "a C callback", "stepping", "SIGTERM")
    code, line = LINES["SIGTERM"]
    assert (done.returncode, _said(done)) == (code, [line]), done.stderr
    assert not (tmp_path / "take.npz").exists()


@pytest.fixture
def installed() -> object:
    """`stops.handle` on the stopping signals, nothing remembered before or after."""
    stops.taken()
    with stops.stops_by_exception():
        yield
    stops.taken()


@pytest.mark.usefixtures("installed")
def test_a_signal_inside_a_deferred_region_waits_for_the_next_check() -> None:
    with pytest.raises(KeyboardInterrupt), stops.deferred():
        signal.raise_signal(signal.SIGINT)  # kept: the next line runs
        kept = stops.received()
        assert isinstance(kept, KeyboardInterrupt)
        stops.check()
    stops.taken()
    with pytest.raises(stops.Terminated, match=r"^SIGHUP$"), stops.deferred():
        signal.raise_signal(signal.SIGHUP)  # kept, then raised as the region ends


@pytest.mark.usefixtures("installed")
def test_a_second_signal_while_one_is_kept_raises_at_once() -> None:
    reached = []
    with pytest.raises(KeyboardInterrupt), stops.deferred():
        signal.raise_signal(signal.SIGINT)
        reached.append("first kept")
        signal.raise_signal(signal.SIGINT)
        reached.append("second kept")
    assert reached == ["first kept"]


@pytest.mark.usefixtures("installed")
def test_outside_a_deferred_region_a_signal_raises_at_once_and_is_remembered() -> None:
    with pytest.raises(stops.Terminated):
        signal.raise_signal(signal.SIGTERM)
    assert isinstance(stops.received(), stops.Terminated)
    with pytest.raises(stops.Terminated):  # swallowed somewhere: the next check says it again
        stops.check()
    stops.taken()
    stops.check()  # reported: nothing left


def test_without_the_handler_nothing_is_remembered_or_raised() -> None:
    stops.taken()
    with stops.deferred():
        stops.check()
    assert stops.received() is None
    assert signal.getsignal(signal.SIGINT) is not stops.handle


@pytest.mark.usefixtures("installed")
def test_a_stop_swallowed_by_a_c_callback_is_not_committed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import ctypes

    from ecs_tentacles.output.atomic import atomic_output

    swallowed: list[object] = []  # what ctypes could not raise (else pytest's warning)
    monkeypatch.setattr(sys, "unraisablehook", swallowed.append)
    target = tmp_path / "take.npz"
    with pytest.raises(KeyboardInterrupt), atomic_output(target) as temporary:
        temporary.write_bytes(b"half a take")
        ctypes.CFUNCTYPE(None)(lambda: signal.raise_signal(signal.SIGINT))()  # ignored there
        assert temporary.read_bytes() == b"half a take"  # the writer went on
    assert list(tmp_path.iterdir()) == []
    assert [type(getattr(u, "exc_value", None)) for u in swallowed] == [KeyboardInterrupt]


BLOCKER = """
from ecs_tentacles.plugin import Plugin


class Blocker(Plugin):
    name = "blocker"

    def build_creature(self, world, creature, spec):
        with open({fifo!r}, "rb") as pipe:  # blocks: the test opens it and writes nothing
            pipe.read()
"""


def _reader_came(fifo: Path, process: subprocess.Popen[str]) -> int:
    """The FIFO's write end, once `process` has opened its read end (the plugin is then in
    its read, or a moment before it)."""
    import errno
    import os
    import time

    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and process.poll() is None:
        try:
            return os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        except OSError as error:  # ENXIO: no reader yet
            assert error.errno == errno.ENXIO
            time.sleep(0.05)
    raise AssertionError(f"the build never read the FIFO: {process.communicate()}")


@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM"])
def test_the_first_signal_stops_a_build_blocked_in_a_read(tmp_path: Path, stop: str) -> None:
    """A build blocked in a read (a FIFO no one writes) kept the first signal for a
    creature that never came: validate waited forever. Now it stops within a second or
    so, in one line, with the usual exit code."""
    import os
    import time

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    (tmp_path / "blocker.py").write_text(BLOCKER.format(fifo=str(fifo)))
    creature = {"name": "octo", "tentacles": {"count": 3, "links": 2}}
    scene = {"version": 1, "plugins": {"blocker": {"from": "blocker.py:Blocker"}}}
    (tmp_path / "scene.json").write_text(json.dumps({**scene, "creatures": [creature]}))
    process = subprocess.Popen(
        [sys.executable, "-P", "-m", "ecs_tentacles", "validate", "scene.json", "--allow-systems"],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    writer = None
    try:
        writer = _reader_came(fifo, process)
        process.send_signal(getattr(signal, stop))
        sent = time.monotonic()
        try:
            _, err = process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            raise AssertionError("the signal was kept for a creature that never came") from None
        took = time.monotonic() - sent
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        if writer is not None:
            os.close(writer)
    code, line = LINES[stop]
    assert (process.returncode, err.splitlines()) == (code, [line])
    assert took < 10


@pytest.mark.usefixtures("installed")
def test_a_kept_stop_is_raised_in_a_read_that_blocks() -> None:
    """Inside a deferred region, a stop kept while the main thread sleeps in a read is
    raised there, as a second signal would be, instead of waiting for a check."""
    import os
    import threading
    import time

    read_end, write_end = os.pipe()
    main = threading.main_thread().ident
    sender = threading.Timer(0.2, signal.pthread_kill, (main, signal.SIGINT))
    rescue = threading.Timer(10.0, os.write, (write_end, b"x"))  # the old way: ends the read
    try:
        sender.start()
        rescue.start()
        started = time.monotonic()
        with pytest.raises(KeyboardInterrupt), stops.deferred():
            os.read(read_end, 1)  # nothing is ever written
        assert time.monotonic() - started < 5
    finally:
        sender.cancel()
        rescue.cancel()
        os.close(read_end)
        os.close(write_end)


@pytest.mark.usefixtures("installed")
def test_a_kept_stop_waits_for_the_check_while_the_main_thread_waits_for_a_thread() -> None:
    """Waiting for a lock (a frame's physics threads) is not blocking in a read: the stop
    stays kept until the frame's work is done and the next check comes."""
    import threading
    import time

    done = threading.Event()
    reached = []
    main = threading.main_thread().ident
    assert main is not None

    def work() -> None:
        signal.pthread_kill(main, signal.SIGINT)
        time.sleep(1.0)  # longer than a kept stop waits for a read
        done.set()

    worker = threading.Thread(target=work)
    with pytest.raises(KeyboardInterrupt), stops.deferred():
        worker.start()
        done.wait()
        reached.append("the work")
        stops.check()
    worker.join()
    assert reached == ["the work"]
