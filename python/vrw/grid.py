"""Grids of gaits over two parameters, serially or on a ``dask.distributed`` cluster.

A grid ``x`` by ``y`` (e.g. viscosity by stiffness) is computed one row at a time: each row is a
``vrw.sweep`` of ``x`` at one value of ``y``, so continuation from one gait to the next still works inside a
row, and each row is one task for a worker. The rows are independent; their results are gathered into
2-D arrays of shape ``(len(y), len(x))``. A row computes the same numbers wherever it runs, so the grid is
bit for bit the one computed serially (``client=None``).

>>> from dask.distributed import Client, LocalCluster
>>> import numpy as np, vrw
>>> from vrw.grid import gait_grid
>>> with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
...     grid = gait_grid(client, vrw.Params(), x=("viscosity", np.linspace(20, 80, 7)),
...                      y=("stiffness", [400.0, 500.0, 600.0]))
>>> grid["sweep"]["lambda_4_plus"].shape
(3, 7)

On an HPC cluster, the same call takes a client of a ``dask-jobqueue`` cluster (see the README, "On a
cluster").
"""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ._vrw import Params
from .results import Grid, Table

Axis = Tuple[str, Sequence[float]]

__all__ = ["gait_grid", "grid_row"]


def grid_row(
    params: Params,
    x: str,
    x_values: Sequence[float],
    options: Dict[str, Any],
) -> Dict[str, Any]:
    """One row of a grid: ``vrw.sweep(params, x, x_values, **options)`` (what a worker runs)."""
    from . import sweep  # the package's, which returns result objects

    return sweep(params, x, list(x_values), **options)


def gait_grid(
    client: Optional[Any],
    params: Params,
    x: Axis,
    y: Axis,
    *,
    initial: Optional[Sequence[float]] = None,
    **options: Any,
) -> Grid:
    """The gaits on the grid ``x`` by ``y``: one ``vrw.sweep`` of ``x`` per value of ``y``.

    ``client`` is a ``dask.distributed.Client`` (each row is one task, submitted to its workers), or
    ``None`` to compute the rows here, one after the other. ``x`` and ``y`` are ``(key, values)`` pairs of
    numeric ``Params`` keys (``vrw.Params.numeric_keys()``). ``initial`` and the other keyword arguments
    are passed to ``vrw.sweep`` (each row starts its continuation from ``initial``).

    Returns a ``Grid`` (a dict; ``.to_xarray()`` gives an ``xarray.Dataset``) with ``x`` and ``y`` (the keys), ``x_values`` and ``y_values`` (float arrays),
    ``sweep`` (every column of ``sweep.csv`` as an array of shape ``(len(y), len(x))``), ``thresholds``
    (one list of threshold dicts per row) and ``gaits_found`` (the number of grid points with a gait).
    An invalid ``y`` value raises ``vrw.ConfigError`` before anything is submitted.
    """
    x_name, x_values = x[0], np.asarray(x[1], dtype=float)
    y_name, y_values = y[0], np.asarray(y[1], dtype=float)
    if x_values.ndim != 1 or y_values.ndim != 1:
        raise ValueError("gait_grid: x and y values must be 1-D")
    rows = [params.replace(**{y_name: float(v)}) for v in y_values]
    row_options = dict(options, initial=initial)
    xs = [float(v) for v in x_values]
    if client is None:
        results: List[Dict[str, Any]] = [grid_row(p, x_name, xs, row_options) for p in rows]
    else:
        futures = client.map(
            grid_row,
            rows,
            x=x_name,
            x_values=xs,
            options=row_options,
            pure=False,
        )
        results = client.gather(futures)
    columns = results[0]["sweep"].keys() if results else []
    return Grid(
        {
            "x": x_name,
            "y": y_name,
            "x_values": x_values,
            "y_values": y_values,
            "sweep": Table({c: np.stack([r["sweep"][c] for r in results]) for c in columns}),
            "thresholds": [r["thresholds"] for r in results],
            "gaits_found": sum(r["gaits_found"] for r in results),
        }
    )
