"""vrw: passive dynamic walking of a viscoelastic-legged rimless wheel, and of other planar walkers, from Python.

A front to the vrw Rust library: the same parameters (``Params``, every key of a vrw TOML file), the same
jobs as the command line (``simulate``, ``find_gait``, ``sweep``, ``map``, ``orbit``, ``basin``,
``continue_family``, ``animate``), with its defaults, checks and numbers, and the same names for their results
(the columns of its CSV files as ``Table``s, ``.to_pandas()``; the fields of its JSON files; grids
``.to_xarray()``). ``vrw.plot`` draws the command line's figures on matplotlib axes; ``vrw.grid`` spreads maps,
orbit diagrams, basins and grids of sweeps over a Dask cluster. Computation runs in Rust with the GIL released;
``Params`` and every result pickle, so they travel to worker processes.

**Other walkers.** ``Params(model="simplest")`` (Garcia's simplest walking model), ``"compass"`` (Goswami's
compass gait), ``"telescopic"`` (the compass gait with the paper's viscoelastic legs) or the path of a walker
described in a TOML file (``"models/compass.toml"``) holds that walker's parameters (``Params(model="compass",
slope=0.05, hip_mass=10)``; ``.model``, ``.parameter_keys()``), validated as ``vrw --model NAME --set
key=value`` does. ``find_gait``, ``simulate``, ``sweep``, ``continue_family``, ``orbit``, ``map`` and ``basin``
run the command line's ``--model`` jobs on it, with the same numbers, and ``animate`` draws its walks as ``vrw
animate`` draws its ``vrw simulate --model`` runs; their sections and tables are named by the model's
coordinates and their results carry ``model``. An option a model does not take raises ``ConfigError`` naming
the model and the option. ``vrw.plot.sweep``, ``vrw.plot.orbit`` and ``vrw.plot.run`` draw a walker's results,
and ``vrw.grid.gait_grid`` spreads its sweeps.

**Long jobs.** ``sweep``, ``map``, ``orbit`` and ``basin`` (another walker's ``map`` and ``basin``) take
``progress``: a callable ``progress(done,
total)`` called on the calling thread as points finish, or ``True`` for a tqdm bar (``pip install tqdm``).
Ctrl-C (``KeyboardInterrupt``) stops any job within about a second: the job stops starting points, the
points under way stop, and what was computed is discarded (a result is whole or not returned at all), but for
``map`` stopped while its curves are traced: its gaits are complete, and the exception carries them as
``partial`` (the result without curves, with ``interrupted`` saying so). The next call runs normally. An exception raised by the ``progress`` callable stops the job the same way. To keep
what a long study has computed, split it into several calls (e.g. a map in parts of rows, ``rows=``).

>>> import vrw
>>> p = vrw.Params(viscosity=37)
>>> gait = vrw.find_gait(p)
>>> gait["status"], gait["stable"], bool(abs(gait["floquet_multipliers"]).max() < 1)
('found', True, True)
>>> walker = vrw.find_gait(vrw.Params(model="simplest", slope=0.009))
>>> walker["model"], round(walker["section"]["theta"], 9), round(walker["period"], 9), walker["stable"]
('simplest', 0.200310901, 3.882463753, True)
"""

from typing import Any, Optional, Sequence, Union

import numpy as np

from . import _progress, _vrw
from ._vrw import (
    ConfigError,
    Params,
    WalkError,
    __version__,
    linspace,
)
from . import plot
from ._animate import animate, record_params, record_walk
from .results import (
    BasinResult,
    FamilyResult,
    GaitResult,
    MapResult,
    OrbitResult,
    Grid,
    Result,
    Run,
    SweepResult,
    Table,
    wrap_tables,
)


def simulate(
    params: Params,
    steps: int = 20,
    initial: Optional[Sequence[float]] = None,
    trajectory: bool = True,
    sample_dt: float = 0.005,
) -> Run:
    """Walk ``steps`` steps from ``initial`` (``vrw simulate``): a ``Run``, the fields of ``summary.json`` with
    ``steps`` and ``trajectory`` as ``Table``s (``.to_pandas()``). See ``vrw._vrw.simulate``. The ``Run``
    keeps the arguments it was walked with (not as a field), so that ``vrw.animate`` draws this very walk."""
    run = Run(_vrw.simulate(params, steps, initial, trajectory, sample_dt))
    wrap_tables(run, ["steps", "trajectory"])
    record_walk(run, params, steps, initial, sample_dt)
    return run


def find_gait(params: Params, initial: Optional[Sequence[float]] = None, **options: Any) -> GaitResult:
    """Find the gait (``vrw gait``): a ``GaitResult``, the fields of ``gait.json``. See
    ``vrw._vrw.find_gait``."""
    result = GaitResult(_vrw.find_gait(params, initial, **options))
    record_params(result, params)
    return result


def sweep(
    params: Params,
    param: str,
    values: Union[Sequence[float], "np.ndarray"],
    *,
    initial: Optional[Sequence[float]] = None,
    **options: Any,
) -> SweepResult:
    """Sweep ``param`` over ``values`` (``vrw sweep``): a ``SweepResult`` whose ``sweep`` is a ``Table``
    (``.to_pandas()``). See ``vrw._vrw.sweep``."""
    options = _progress.resolve(options, f"sweep {param}")
    result = SweepResult(_vrw.sweep(params, param, values, initial=initial, **options))
    wrap_tables(result, ["sweep"])
    return result


def basin(params: Params, **options: Any) -> BasinResult:
    """The basin of the gait on a slice of the section (``vrw basin``): a ``BasinResult``, the fields of
    ``basin.json`` with ``points`` (the columns of ``basin.csv``) as a ``Table``; ``.to_xarray()`` gives the
    grid over the slice's two coordinates. See ``vrw._vrw.basin`` for the options."""
    result = BasinResult(_vrw.basin(params, **_progress.resolve(options, "basin")))
    wrap_tables(result, ["points"])
    return result


def continue_family(params: Params, param: str = "viscosity", **options: Any) -> FamilyResult:
    """Follow the gait family through the gait at ``start`` in ``param`` by pseudo-arclength continuation
    (``vrw continue``): a ``FamilyResult``, the fields of ``special_points.json`` with ``branch`` (the columns of
    ``branch.csv``) as a ``Table``, and with ``two_param`` ``curve_points`` (the columns of ``curves.csv``) as a
    ``Table``; with ``extremum`` (a list of monitored quantities) their extrema are special points ``EX`` and
    ``monitored`` (the columns of ``monitored.csv``) a ``Table``. See ``vrw._vrw.continue_family`` for the
    options."""
    result = FamilyResult(_vrw.continue_family(params, param, **options))
    wrap_tables(result, ["branch", "curve_points", "monitored"])
    return result


def map(params: Params, **options: Any) -> MapResult:
    """The gait over a grid of two parameters and the threshold curves across it (``vrw map``, without the
    figure): a ``MapResult``, the fields of ``curves.json`` (another walker's: of its ``map.json``) with ``map``
    (the columns of ``map.csv``) as a ``Table``; ``to_xarray()`` gives the grid over both parameters. Ctrl-C
    while the curves (thresholds) are traced raises ``KeyboardInterrupt`` with the complete gaits as its
    ``partial``, a ``MapResult`` too. See ``vrw._vrw.map`` for the options."""
    try:
        result = MapResult(_vrw.map(params, **_progress.resolve(options, "map")))
    except KeyboardInterrupt as stopped:
        # The complete gaits that go with Ctrl-C, as the result they are.
        partial = getattr(stopped, "partial", None)
        if isinstance(partial, dict):
            stopped.partial = MapResult(partial)
            wrap_tables(stopped.partial, ["map"])
        raise
    wrap_tables(result, ["map"])
    return result


def orbit(params: Params, param: str = "viscosity", **options: Any) -> OrbitResult:
    """The orbit diagram along ``param`` and the period-1 branch beside it (``vrw orbit``, without the figure):
    an ``OrbitResult``, the fields of ``orbit.json`` with ``orbit`` and ``branch`` (the columns of ``orbit.csv``
    and ``branch.csv``) as ``Table``s. See ``vrw._vrw.orbit`` for the options."""
    result = OrbitResult(_vrw.orbit(params, param, **_progress.resolve(options, f"orbit {param}")))
    wrap_tables(result, ["orbit", "branch"])
    return result


__all__ = [
    "BasinResult",
    "FamilyResult",
    "ConfigError",
    "GaitResult",
    "MapResult",
    "OrbitResult",
    "Grid",
    "Params",
    "Result",
    "Run",
    "SweepResult",
    "Table",
    "WalkError",
    "__version__",
    "animate",
    "basin",
    "continue_family",
    "find_gait",
    "linspace",
    "map",
    "orbit",
    "plot",
    "simulate",
    "sweep",
]
