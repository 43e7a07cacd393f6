"""vrw: passive dynamic walking of a viscoelastic-legged rimless wheel, from Python.

A front to the vrw Rust library: the same parameters (``Params``, every key of a vrw TOML file), the same
jobs as the command line (``simulate``, ``find_gait``, ``sweep``) and the same names for their results (the
columns of ``steps.csv``, ``trajectory.csv`` and ``sweep.csv``, the fields of ``summary.json``,
``gait.json`` and ``thresholds.json``). Computation runs in Rust with the GIL released; ``Params`` and every
result pickle, so they travel to worker processes (see ``vrw.grid`` for grids of gaits on a Dask cluster).

>>> import vrw
>>> p = vrw.Params(viscosity=37)
>>> gait = vrw.find_gait(p)
>>> gait["status"], gait["stable"], abs(gait["floquet_multipliers"]).max() < 1
('found', True, True)
"""

from ._vrw import (
    ConfigError,
    Params,
    WalkError,
    __version__,
    find_gait,
    linspace,
    simulate,
    sweep,
)

__all__ = [
    "ConfigError",
    "Params",
    "WalkError",
    "__version__",
    "find_gait",
    "linspace",
    "simulate",
    "sweep",
]
