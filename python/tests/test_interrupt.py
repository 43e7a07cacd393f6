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
