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
# is stopped. The direct light (the first solution) takes well under a second.
LONG = dict(solver="progressive", max_elements=12000, epsilon=1e-12, max_shots=10**9)
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


def test_an_interrupt_before_any_solution_cancels_the_run():
    interrupt = penumbra.Interrupt()
    interrupt.set()
    scene = penumbra.Scene.builtin("cornell")
    with pytest.raises(penumbra.RunCancelled):
        penumbra.run(scene, interrupt=interrupt, max_elements=2000)
    interrupt.clear()
    assert not interrupt.is_set
    assert not penumbra.run(scene, interrupt=interrupt, max_elements=2000).partial


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
