"""Ctrl-C during a long computation: KeyboardInterrupt arrives within about a second, the partial result is
discarded, and the next call runs normally."""

import _thread
import threading
import time

import pytest

import vrw


def test_ctrl_c_during_a_long_sweep_raises_keyboard_interrupt_within_a_second():
    values = vrw.linspace(20, 140, 4000)  # tens of seconds of work
    delay = 0.5
    timer = threading.Timer(delay, _thread.interrupt_main)  # what SIGINT does
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        vrw.sweep(vrw.Params(), "viscosity", values)
    assert time.monotonic() - start < delay + 1.0
    # The library's interrupt flag is cleared: the next sweep is whole.
    result = vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(40, 60, 3))
    assert len(result["sweep"]["viscosity"]) == 3


@pytest.mark.parametrize(
    "job",
    [
        # A walk of about ten seconds: Ctrl-C stops it inside a step.
        lambda: vrw.simulate(vrw.Params(), steps=50000, trajectory=False),
        # A gait search whose transient walks about ten seconds.
        lambda: vrw.find_gait(vrw.Params(), transient_steps=50000),
    ],
    ids=["simulate", "find_gait"],
)
def test_ctrl_c_during_a_long_walk_or_gait_search_raises_within_a_second(job):
    delay = 0.5
    timer = threading.Timer(delay, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        job()
    assert time.monotonic() - start < delay + 1.0
    # The next call runs normally.
    assert vrw.find_gait(vrw.Params())["status"] == "found"
