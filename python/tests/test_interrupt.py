"""Stopping a run: an Interrupt set from another thread returns the best solution so far;
Ctrl-C raises RunInterrupted carrying it. Either way the run ends promptly."""

from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pytest

import penumbra

# Progressive refinement to a tolerance it cannot reach in the test's time: it shoots until it
# is stopped (to 1e-12 it took 2.2 s, near the stop). The direct light (the first solution) takes
# well under a second.
LONG = dict(solver="progressive", max_elements=12000, epsilon=1e-100, max_shots=10**9)
STOP_AFTER = 2.5
PROMPT = 2.0  # seconds a stop may take to end the run


def _assert_partial(solution: penumbra.Solution) -> None:
    assert solution.partial
    assert solution.report["solver"]["stop"] == "interrupted"
    assert np.isfinite(solution.radiosity).all() and (solution.radiosity >= 0).all()
    assert solution.indirect.any()  # shooting had begun


def test_an_interrupt_from_another_thread_returns_a_partial_solution():
    interrupt = penumbra.Interrupt()
    threading.Timer(STOP_AFTER, interrupt.set).start()
    started = time.perf_counter()
    solution = penumbra.run(penumbra.Scene.builtin("cornell"), interrupt=interrupt, **LONG)
    assert time.perf_counter() - started < STOP_AFTER + PROMPT
    assert interrupt.is_set
    _assert_partial(solution)


def test_an_interrupt_before_any_mesh_keeps_the_least_mesh_lit():
    interrupt = penumbra.Interrupt()
    interrupt.set()
    scene = penumbra.Scene.builtin("cornell")
    stopped = penumbra.run(scene, interrupt=interrupt, max_elements=2000)
    assert stopped.partial
    assert stopped.report["stopped"] == {
        "stage": "discontinuities",
        "reason": "interrupted",
        "kept": "least_mesh_direct",
    }
    # The scene's least mesh, its polygons' own triangles, with the direct light only.
    assert stopped.report["counts"]["triangles"] < 2 * len(scene) + 8
    assert np.isfinite(stopped.radiosity).all() and (stopped.radiosity >= 0).all()
    assert stopped.direct.any() and not stopped.indirect.any()
    interrupt.clear()
    assert not interrupt.is_set
    whole = penumbra.run(scene, interrupt=interrupt, max_elements=2000)
    assert not whole.partial and "stopped" not in whole.report


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(), reason="signals reach the main thread")
def test_ctrl_c_raises_with_the_partial_solution():
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    threading.Timer(STOP_AFTER, os.kill, (os.getpid(), signal.SIGINT)).start()
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt) as raised:
        penumbra.run(penumbra.Scene.builtin("cornell"), **LONG)
    assert time.perf_counter() - started < STOP_AFTER + PROMPT
    assert isinstance(raised.value, penumbra.RunInterrupted)
    _assert_partial(raised.value.solution)


MAIN_THREAD = pytest.mark.skipif(
    threading.current_thread() is not threading.main_thread(), reason="signals reach the main thread"
)


@MAIN_THREAD
def test_a_second_ctrl_c_returns_at_once():
    # The first Ctrl-C stops the search for discontinuities; lighting the least mesh of three
    # thousand boxes (60,008 vertices) then takes a quarter of a second of exact direct light
    # whatever the interrupt, and the second Ctrl-C does not wait for it (the run ends on its
    # own in the background).
    for delay in (0.3, 0.4):
        threading.Timer(delay, os.kill, (os.getpid(), signal.SIGINT)).start()
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt) as raised:
        penumbra.run(penumbra.Scene.builtin("boxworld-3000"), direct_only=True)
    assert time.perf_counter() - started < 0.4 + PROMPT
    assert not isinstance(raised.value, penumbra.RunInterrupted)


class Timeout(Exception):
    pass


@MAIN_THREAD
def test_another_signal_handlers_exception_is_raised_as_it_is():
    def alarm(signum, frame):
        raise Timeout("too slow")

    previous = signal.signal(signal.SIGALRM, alarm)
    try:
        signal.setitimer(signal.ITIMER_REAL, STOP_AFTER)
        with pytest.raises(Timeout, match="too slow") as raised:
            penumbra.run(penumbra.Scene.builtin("cornell"), **LONG)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    _assert_partial(raised.value.solution)


@MAIN_THREAD
def test_ctrl_c_stops_a_reference_between_points():
    scene = penumbra.Scene.builtin("cornell")
    floor = [[x, 0.0, z] for x in np.linspace(50, 500, 10) for z in np.linspace(50, 500, 10)]
    threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT)).start()
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        penumbra.reference(scene, floor, paths=200_000)
    assert time.perf_counter() - started < 1.0 + PROMPT


DAEMON = """
import sys, threading, time, penumbra
scene = penumbra.Scene.builtin("boxworld")
work = {
    "run": lambda: penumbra.run(scene, max_elements=12000),
    "progress": lambda: penumbra.run(scene, max_elements=12000, progress=lambda *a: None),
    "direct_light": lambda: penumbra.direct_light(scene, [[0.5, 0.5, 0.0]] * 200000, [0, 0, 1]),
}[sys.argv[1]]
threading.Thread(target=work, daemon=True).start()
time.sleep(0.3)
"""


@pytest.mark.parametrize("work", ["run", "progress", "direct_light"])
def test_the_interpreter_exits_cleanly_with_work_under_way(work):
    import subprocess
    import sys

    for _ in range(3):
        done = subprocess.run([sys.executable, "-c", DAEMON, work], capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, (done.returncode, done.stderr)
