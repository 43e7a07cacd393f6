"""Ctrl-C during a long computation: KeyboardInterrupt arrives within about a second, the partial result is
discarded, and the next call runs normally."""

import _thread
import signal
import threading
import time

import pytest

import vrw

# `_thread.interrupt_main` does nothing where Python does not handle SIGINT: a process started in the
# background by a shell without job control (`.ci/run &`) inherits SIGINT ignored. Ctrl-C is what these tests
# are about, so they install Python's own handler.
signal.signal(signal.SIGINT, signal.default_int_handler)


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
        # Another walker's jobs (vrw.Params(model=...)), each of tens of seconds.
        lambda: vrw.simulate(vrw.Params(model="simplest"), steps=1_000_000, trajectory=False),
        lambda: vrw.sweep(vrw.Params(model="compass"), "slope", vrw.linspace(0.01, 0.09, 20000)),
        lambda: vrw.find_gait(vrw.Params(model="telescopic"), transient_steps=100_000),
        lambda: vrw.map(vrw.Params(model="compass"), x="slope", x_range=(0.05, 0.09), nx=200, y="hip_mass",
                        y_range=(5.0, 20.0), ny=200),
        lambda: vrw.basin(vrw.Params(model="compass"), nx=400, ny=400),
        lambda: vrw.animate(vrw.simulate(vrw.Params(model="compass"), steps=2000, trajectory=False), fps=50),
    ],
    ids=["simulate", "find_gait", "walker simulate", "walker sweep", "telescopic find_gait", "walker map",
         "walker basin", "walker animate"],
)
def test_ctrl_c_during_a_long_job_raises_within_a_second(job):
    delay = 0.5
    timer = threading.Timer(delay, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        job()
    assert time.monotonic() - start < delay + 1.0
    # The next call runs normally.
    assert vrw.find_gait(vrw.Params())["status"] == "found"


@pytest.mark.parametrize(
    "job, total",
    [
        (lambda progress: vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(20, 80, 40), progress=progress), 40),
        (lambda progress: vrw.map(vrw.Params(), nx=4, ny=3, curves=False, progress=progress), 12),
        (lambda progress: vrw.orbit(vrw.Params(), range=(20, 60), points=6, transient=4, steps=4,
                                    branch=False, progress=progress), 6),
        (lambda progress: vrw.basin(vrw.Params(), nx=4, ny=5, max_steps=10, progress=progress), 20),
        # Another walker's map and basin (vrw.Params(model=...)).
        (lambda progress: vrw.map(vrw.Params(model="compass"), x="slope", x_range=(0.05, 0.06), nx=4,
                                  y="hip_mass", y_range=(9.0, 10.0), ny=3, progress=progress), 12),
        (lambda progress: vrw.basin(vrw.Params(model="simplest"), nx=4, ny=5, max_steps=10, progress=progress),
         20),
    ],
    ids=["sweep", "map", "orbit", "basin", "walker map", "walker basin"],
)
def test_progress_is_reported_on_the_calling_thread_up_to_the_total(job, total):
    calls = []
    job(lambda done, of: calls.append((done, of, threading.get_ident())))
    assert calls, "never reported"
    assert all(of == total for _, of, _ in calls)
    done = [d for d, _, _ in calls]
    assert done == sorted(set(done)) and done[-1] == total
    assert {t for _, _, t in calls} == {threading.get_ident()}


def test_an_exception_in_the_progress_callback_stops_the_job():
    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop(f"{done} of {total}")

    start = time.monotonic()
    with pytest.raises(Stop):
        vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(20, 140, 4000), progress=stop)
    assert time.monotonic() - start < 1.5
    with pytest.raises(TypeError, match="progress must be"):
        vrw.sweep(vrw.Params(), "viscosity", [40.0, 50.0], progress="yes")


def test_progress_true_draws_a_tqdm_bar(capsys):
    pytest.importorskip("tqdm")
    result = vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(40, 60, 5), progress=True)
    assert result["gaits_found"] == 5
    assert "5/5" in capsys.readouterr().err


#: The wheel's map and a walker's (whose curves are its thresholds bisected along the rows).
WALKER_MAP = dict(x="slope", x_range=(0.07, 0.08), nx=5, y="hip_mass", y_range=(8.0, 12.0), ny=40)


@pytest.mark.parametrize(
    "params, grid, wait, during",
    [
        # After the last gait, the rows' backward fill and family numbers (part of the gaits, not counted: a
        # fraction of a second, more on a busy machine), then the curves (twenty seconds).
        (vrw.Params(), dict(nx=21, ny=21), 0.3, "while tracing the threshold curves"),
        # After the last gait, at once the thresholds: a second and a half on an idle machine (a bisection in
        # each of the 40 rows), three times as long as the gaits.
        (vrw.Params(model="compass"), WALKER_MAP, 0.1, "while bisecting the thresholds"),
    ],
    ids=["wheel", "walker"],
)
def test_ctrl_c_while_a_maps_curves_are_traced_keeps_its_gaits(params, grid, wait, during):
    """The map's gaits are complete when its curves are traced: Ctrl-C then hands them on with the
    KeyboardInterrupt (as ``partial``, a ``MapResult`` without curves), instead of throwing them away."""
    import numpy as np

    whole = vrw.map(params, curves=False, **grid)
    # The last gait's progress call can come before the rows' backward fill, which belongs to the gaits: Ctrl-C
    # there stops the gaits, and rightly hands nothing on. The interrupt is meant for the curves after it, so a
    # try that lands in the fill (on a busy machine) is made again with a longer delay.
    for delay in (wait, 2 * wait, 4 * wait, 8 * wait):
        started = []

        def progress(done, total):
            if done == total and not started:
                started.append(True)
                threading.Timer(delay, _thread.interrupt_main).start()

        with pytest.raises(KeyboardInterrupt) as stopped:
            vrw.map(params, progress=progress, **grid)
        if hasattr(stopped.value, "partial"):
            break
    partial = stopped.value.partial
    assert isinstance(partial, vrw.MapResult) and during in partial["interrupted"]
    assert partial.get("curves", []) == [] and partial["thresholds"] == []
    assert partial["gaits_found"] == whole["gaits_found"] > 0
    for column in ("status", "period", "max_floquet"):
        a, b = np.asarray(partial["map"][column]), np.asarray(whole["map"][column])
        if a.dtype.kind == "f":
            assert np.array_equal(a, b, equal_nan=True), column
        else:
            assert list(a) == list(b), column
