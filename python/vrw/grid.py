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

The map's gaits and the basin are spread the same way, in parts of rows (``map_grid``, ``basin_grid``): each
part is computed exactly as the whole job computes those rows (``vrw.map(..., rows=(start, end))``), so the
gathered result is bit for bit ``vrw.map(..., curves=False)`` or ``vrw.basin(...)``. An orbit diagram is one
row continued along the parameter; ``orbit_grid`` splits it as ``vrw.orbit`` does on one machine's cores:
the coarse pass (every tenth value, each continuing the one before) is one task, then the values between
two coarse values are a task each, started from where the coarse value's walk ended, and the period-1
branch is one more task beside them. The map's threshold
curves need every row's gaits in one process (they continue gaits across rows), so ``map_grid`` computes the
gaits only; ``vrw.map`` on one machine draws the curves.

**Failures.** A task is a pure function of its arguments (no state is shared between tasks), so when a worker
dies (killed, out of memory, its node lost) the scheduler recomputes the tasks it held on another worker and
the result is still bit for bit the serial one; only the lost tasks' time is lost. A task that raises (e.g. an
invalid parameter value) raises here, with the library's message.

On an HPC cluster, the same call takes a client of a ``dask-jobqueue`` cluster (see the README, "On a
cluster").
"""

import operator
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ._vrw import ConfigError, Params
from .results import BasinResult, Grid, MapResult, OrbitResult, Table

Axis = Tuple[str, Sequence[float]]

__all__ = ["basin_grid", "gait_grid", "grid_row", "map_grid", "orbit_grid"]


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


def _parts(rows: int, rows_per_task: int) -> List[Tuple[int, int]]:
    """The row ranges ``(start, end)`` of the tasks: ``rows_per_task`` rows each, the last one shorter."""
    if isinstance(rows_per_task, bool) or not isinstance(rows_per_task, int) or rows_per_task < 1:
        raise ConfigError(f"invalid value {rows_per_task!r} for `rows_per_task`: a whole number >= 1")
    return [(start, min(start + rows_per_task, rows)) for start in range(0, rows, rows_per_task)]


def _rows(options: Dict[str, Any], default: int) -> int:
    """The job's number of rows ``ny`` (at least 1: an invalid ``ny`` is then refused, with the library's
    message, by the first part)."""
    try:
        return max(operator.index(options.get("ny", default)), 1)
    except TypeError:
        return 1


def _run_rows(client: Optional[Any], job: Any, params: Params, rows: int, rows_per_task: int,
              options: Dict[str, Any]) -> List[Dict[str, Any]]:
    """``job(params, rows=part, **options)`` for every part of ``rows_per_task`` of the job's rows (``ny``,
    ``rows`` by default), in the parts' order. The first part runs here, so that the options' errors are raised
    before anything is submitted; the others here too (``client=None``) or as one task each on ``client``'s
    workers."""
    parts = _parts(_rows(options, rows), rows_per_task)
    first = job(params, rows=parts[0], **options)
    if client is None:
        return [first] + [job(params, rows=part, **options) for part in parts[1:]]
    futures = client.map(lambda part: job(params, rows=part, **options), parts[1:], pure=False)
    return [first] + list(client.gather(futures))


def _outcomes(results: List[Dict[str, Any]]) -> Dict[str, int]:
    """The parts' ``outcomes`` counts added up, by name in order (as the library's map of them)."""
    outcomes: Dict[str, int] = {}
    for r in results:
        for kind, n in r["outcomes"].items():
            outcomes[kind] = outcomes.get(kind, 0) + n
    return dict(sorted(outcomes.items()))


def _concatenate(tables: List[Dict[str, Any]]) -> Table:
    """Tables of the same columns, one after the other, each column of the dtype the whole table has."""
    return Table({name: _join([np.asarray(t[name]) for t in tables]) for name in tables[0]})


def _join(parts: List[Any]) -> Any:
    """One column from its parts. A column's dtype follows its values as ``pandas.read_csv`` would (see
    ``vrw.results``): a part whose cells are all empty comes as float64 NaN whatever the column holds, a count
    column with an empty cell as float64. So the whole column takes the kind of its first part with a value,
    and its empty parts that kind's empty value ('' for words, False for flags); counts are float64 if any part
    has an empty cell."""
    empty = [a.dtype.kind == "f" and bool(np.isnan(a).all()) for a in parts]
    kinds = [a.dtype.kind for a, e in zip(parts, empty) if not e]
    if not kinds:
        return np.concatenate(parts)
    if kinds[0] == "U":
        return np.concatenate([np.full(len(a), "") if e else a for a, e in zip(parts, empty)])
    if kinds[0] == "b":
        return np.concatenate([np.zeros(len(a), bool) if e else a for a, e in zip(parts, empty)])
    if any(a.dtype.kind == "f" for a in parts):
        return np.concatenate([a.astype(np.float64) for a in parts])
    return np.concatenate(parts)


def map_grid(client: Optional[Any], params: Params, *, rows_per_task: int = 1, **options: Any) -> MapResult:
    """The gaits of ``vrw.map(params, curves=False, **options)``, ``rows_per_task`` rows of ``y`` per task on
    ``client``'s workers (``None``: here, part after part): a ``MapResult`` bit for bit the one ``vrw.map``
    computes in one process (``map``, ``gaits_found``, ``points``, ``warnings``), without curves (they need every
    row in one process). The options are ``vrw.map``'s, checked by the first part before the others start.
    """
    if options.get("curves", False) or options.get("second_route", False):
        raise ConfigError(
            "map_grid computes the map's gaits (curves=False): the curves need every row in one process, "
            "use vrw.map for them"
        )
    from . import _vrw

    results = _run_rows(client, _vrw.map, params, 21, rows_per_task, dict(options, curves=False))
    merged = dict(results[0])
    merged["gaits_found"] = sum(r["gaits_found"] for r in results)
    merged["points"] = sum(r["points"] for r in results)
    merged["warnings"] = [w for r in results for w in r["warnings"]]
    merged["map"] = _concatenate([r["map"] for r in results])
    return MapResult(merged)


def basin_grid(client: Optional[Any], params: Params, *, rows_per_task: int = 4, **options: Any) -> BasinResult:
    """``vrw.basin(params, **options)`` with ``rows_per_task`` rows of the grid per task on ``client``'s
    workers (``None``: here, part after part): a ``BasinResult`` bit for bit the one ``vrw.basin`` computes in
    one process. Every task finds the gait again (a few milliseconds: the same gait, computed the same way).
    The options are ``vrw.basin``'s, checked by the first part before the others start."""
    from . import _vrw

    results = _run_rows(client, _vrw.basin, params, 61, rows_per_task, options)
    merged = dict(results[0])
    merged["outcomes"] = _outcomes(results)
    merged["points"] = _concatenate([r["points"] for r in results])
    return BasinResult(merged)


def orbit_grid(client: Optional[Any], params: Params, param: str = "viscosity", **options: Any) -> OrbitResult:
    """``vrw.orbit(params, param, **options)`` in parts on ``client``'s workers (``None``: here, part after
    part): the coarse pass and the branch first (two tasks), then one task per interval between coarse values.
    An ``OrbitResult`` bit for bit the one ``vrw.orbit`` computes in one process."""
    from . import _vrw

    def part(which: Any) -> Any:
        if client is None:
            return _vrw.orbit(params, param, part=which, **options)
        return client.submit(_vrw.orbit, params, param, part=which, pure=False, **options)

    def result(future: Any) -> Dict[str, Any]:
        return future if client is None else future.result()

    coarse_part, branch_part = part("coarse"), part("branch")
    coarse = result(coarse_part)
    fills = [part(("fill", k, left)) for k, left in enumerate(coarse["ends"])]
    fills = fills if client is None else client.gather(fills)
    branch = result(branch_part)
    # The diagram in the order of the values: each coarse column, then the values up to the next.
    starts = np.concatenate([[0], np.cumsum(coarse["column_rows"])])
    tables = []
    for k, fill in enumerate(fills):
        tables.append(Table({name: column[starts[k] : starts[k + 1]] for name, column in coarse["orbit"].items()}))
        tables.append(fill["orbit"])
    merged = {key: value for key, value in coarse.items() if key not in ("ends", "column_rows")}
    merged["outcomes"] = _outcomes([coarse] + fills)
    merged["branch_gaits"] = branch["branch_gaits"]
    merged["orbit"] = _concatenate(tables)
    if "branch" in branch:
        merged["branch"] = branch["branch"]
    return OrbitResult(merged)
