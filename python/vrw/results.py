"""Result objects of the jobs: what ``vrw.simulate``, ``vrw.find_gait``, ``vrw.sweep`` and ``vrw.grid.gait_grid``
return.

Each is a ``dict`` (the keys of the job's JSON file, so ``result["status"]`` and every dict use keep
working) with attribute access (``result.status``), a short ``repr`` that says what it holds, and
conversions of its tables:

- a ``Table`` (``run.steps``, ``run.trajectory``, ``sweep.sweep``) is a dict of numpy columns keyed like the
  CSV file's header; ``Table.to_pandas()`` is the DataFrame with those column names and dtypes (float64,
  int64, bool, and pandas' own dtype for words), the values ``pandas.read_csv`` of the file gives;
- ``Grid.to_xarray()`` is an ``xarray.Dataset`` with one variable per column of ``sweep.csv`` over the two
  parameters as coordinates.

pandas and xarray are optional: they are imported when a conversion is asked for, and a clear
``ImportError`` says which to install.
"""

from typing import Any, Dict, List

import numpy as np

__all__ = [
    "Result",
    "Table",
    "Run",
    "GaitResult",
    "SweepResult",
    "Grid",
    "BasinResult",
    "MapResult",
    "OrbitResult",
    "FamilyResult",
]


def _optional(module: str) -> Any:
    """Import an optional dependency, or say how to get it."""
    try:
        return __import__(module)
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(f"this conversion needs {module}: pip install {module}") from e


class Result(dict):
    """A job's result: a dict with attribute access (``r.status`` is ``r["status"]``)."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"{type(self).__name__} has no field {name!r}") from None

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | {k for k in self if k.isidentifier()})

    def _fields(self) -> str:
        return ", ".join(self.keys())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._fields()})"


class Table(Result):
    """Columns of a CSV file as numpy arrays, keyed like its header."""

    def to_pandas(self) -> Any:
        """The table as a ``pandas.DataFrame`` (the CSV's column names, in order, and dtypes)."""
        pd = _optional("pandas")
        return pd.DataFrame({name: np.asarray(column) for name, column in self.items()})

    @property
    def rows(self) -> int:
        """Number of rows."""
        return len(next(iter(self.values()))) if self else 0

    def __repr__(self) -> str:
        return f"Table({self.rows} rows: {self._fields()})"


class Run(Result):
    """``vrw.simulate``: the fields of ``summary.json``, with ``steps`` and ``trajectory`` as ``Table``s."""

    def __repr__(self) -> str:
        steps = self.get("steps")
        n = steps.rows if isinstance(steps, Table) else 0
        return f"Run(status={self.get('status')!r}, {n} steps, end_time={self.get('end_time')})"


class GaitResult(Result):
    """``vrw.find_gait``: the fields of ``gait.json``."""

    def __repr__(self) -> str:
        if self.get("status") != "found":
            return f"GaitResult(status={self.get('status')!r}, message={self.get('message')!r})"
        if "model" in self:
            # Another walker's gait (``vrw.Params(model=...)``): its section by the model's coordinates.
            moduli = np.abs(np.asarray(self.get("floquet_multipliers")))
            section = ", ".join(f"{k}={v:.6g}" for k, v in self.get("section", {}).items())
            return (
                f"GaitResult({self['model']}, found, {section}, period {self.get('period'):.6g}, "
                f"lambda_I4={self.get('lambda_I4'):.6g}, {'stable' if self.get('stable') else 'unstable'}, "
                f"max |multiplier| {moduli.max() if moduli.size else float('nan'):.6g})"
            )
        return (
            f"GaitResult(found, period {self.get('period_k')}, branch {self.get('branch')}, "
            f"lambda_I4={self.get('lambda_I4'):.6g}, lambda_2_plus={self.get('lambda_2_plus'):.6g}, "
            f"lambda_4_plus={self.get('lambda_4_plus'):.6g}, {self.get('stability')}, "
            f"max |multiplier| {self.get('max_floquet'):.6g})"
        )


class _WithTable(Result):
    """A result whose main table is its entry ``_table``; ``to_pandas()`` converts that table."""

    _table = ""

    def to_pandas(self) -> Any:
        """The result's table (its CSV file) as a ``pandas.DataFrame``."""
        return self[self._table].to_pandas()


class SweepResult(_WithTable):
    """``vrw.sweep``: ``sweep`` (the columns of ``sweep.csv``, a ``Table``) and ``thresholds``."""

    _table = "sweep"

    def __repr__(self) -> str:
        return (
            f"SweepResult({self.get('param')}: {self['sweep'].rows} points, {self.get('gaits_found')} "
            f"gaits, {len(self.get('thresholds', []))} thresholds)"
        )


class Grid(Result):
    """``vrw.grid.gait_grid``: every column of ``sweep.csv`` over the grid, ``(len(y), len(x))`` each."""

    def to_xarray(self) -> Any:
        """The grid as an ``xarray.Dataset``: one variable per column of ``sweep.csv`` (both parameters'
        own columns excepted), over the coordinates ``y`` and ``x`` named by their parameters."""
        xr = _optional("xarray")
        x, y = self["x"], self["y"]
        data = {
            name: ((y, x), np.asarray(column))
            for name, column in self["sweep"].items()
            if name not in (x, y)
        }
        return xr.Dataset(
            data,
            coords={x: np.asarray(self["x_values"]), y: np.asarray(self["y_values"])},
            attrs={"gaits_found": self["gaits_found"]},
        )

    def __repr__(self) -> str:
        return (
            f"Grid({self['y']} ({len(self['y_values'])}) x {self['x']} ({len(self['x_values'])}): "
            f"{self['gaits_found']} gaits)"
        )


class BasinResult(_WithTable):
    """``vrw.basin``: the fields of ``basin.json`` (the wheel's or another walker's), with ``points`` (the
    columns of ``basin.csv``) a ``Table``."""

    _table = "points"

    def to_xarray(self) -> Any:
        """The grid as an ``xarray.Dataset`` over the slice's two coordinates (``y`` by ``x``): the outcome,
        the steps, the period and the end state of every start."""
        xr = _optional("xarray")
        # The wheel's basin.json has the axes under ``spec``; another walker's has them at the top.
        spec, points = self.get("spec", self), self["points"]
        x, y = spec["x"]["coordinate"], spec["y"]["coordinate"]
        nx, ny = spec["x"]["points"], spec["y"]["points"]
        ix, iy = np.asarray(points["ix"]), np.asarray(points["iy"])
        xs, ys = np.empty(nx), np.empty(ny)
        xs[ix], ys[iy] = np.asarray(points[x]), np.asarray(points[y])
        data = {}
        for name, column in points.items():
            if name in ("ix", "iy", x, y):
                continue
            column = np.asarray(column)
            grid = np.empty((ny, nx), dtype=column.dtype)
            grid[iy, ix] = column
            data[name] = ((y, x), grid)
        return xr.Dataset(data, coords={x: xs, y: ys}, attrs={"outcomes": str(self["outcomes"])})

    def __repr__(self) -> str:
        return f"BasinResult({self['points'].rows} starts: {dict(self['outcomes'])})"


class MapResult(_WithTable):
    """``vrw.map``: the fields of ``curves.json`` (``spec``, ``points``, ``gaits_found``, ``curves``,
    ``thresholds``, ``warnings``, ...; another walker's: of its ``map.json``), with ``map`` (the columns of
    ``map.csv``: one row per grid point, row by row in ``y``) a ``Table``."""

    _table = "map"

    def to_xarray(self) -> Any:
        """The grid as an ``xarray.Dataset`` over the two parameters (``y`` by ``x``, named by their keys):
        every other column of ``map.csv`` as a variable."""
        xr = _optional("xarray")
        # The wheel's curves.json has the axes under ``spec``; another walker's map.json has them at the top.
        spec, points = self.get("spec", self), self["map"]
        x, y = spec["x"]["param"], spec["y"]["param"]
        nx, ny = spec["x"]["points"], spec["y"]["points"]
        xs = np.asarray(points[x])[:nx]
        ys = np.asarray(points[y])[::nx]
        data = {
            name: ((y, x), np.asarray(column).reshape(ny, nx))
            for name, column in points.items()
            if name not in (x, y)
        }
        return xr.Dataset(data, coords={x: xs, y: ys})

    def __repr__(self) -> str:
        if "model" in self:
            # Another walker's map: its changes of stability along the rows, bisected.
            kinds = sorted({t["kind"] for t in self.get("thresholds", [])})
            return (
                f"MapResult({self['model']}, {self['x']['param']} x {self['y']['param']}: gait at "
                f"{self.get('gaits_found')} of {self.get('points')} points, thresholds {kinds})"
            )
        spec = self.get("spec", {})
        names = sorted({c["name"] for c in self.get("curves", [])})
        return (
            f"MapResult({spec.get('x', {}).get('param')} x {spec.get('y', {}).get('param')}: gait at "
            f"{self.get('gaits_found')} of {self.get('points')} points, curves {names})"
        )


class OrbitResult(_WithTable):
    """``vrw.orbit``: the fields of ``orbit.json`` (``spec``, ``outcomes``, ``branch_gaits``, ...), with ``orbit``
    (the columns of ``orbit.csv``: one row per recorded step of every value) and ``branch`` (the columns of
    ``branch.csv``) as ``Table``s."""

    _table = "orbit"

    def __repr__(self) -> str:
        # The wheel's orbit.json has the range under ``spec``; another walker's has it at the top.
        spec = self.get("spec", {}).get("range", self.get("range", {}))
        return (
            f"OrbitResult({spec.get('param')}: {spec.get('points')} values, outcomes "
            f"{dict(self.get('outcomes', {}))})"
        )


class FamilyResult(_WithTable):
    """``vrw.continue_family``: the fields of ``special_points.json`` (``families``, ``special_points``, ...),
    with ``branch`` (the columns of ``branch.csv``: one row per point of every family) a ``Table``."""

    _table = "branch"

    def __repr__(self) -> str:
        kinds = [p["kind"] for p in self.get("special_points", [])]
        if "model" in self:
            # Another walker's family: one family, from its start.
            return (
                f"FamilyResult({self['model']}, {self.get('param')}: {self['branch'].rows} points, "
                f"special points {kinds})"
            )
        return (
            f"FamilyResult({self.get('param')}: {len(self.get('families', []))} families, "
            f"{self['branch'].rows} points, special points {kinds})"
        )


def wrap_tables(result: Dict[str, Any], names: List[str]) -> None:
    """Make the named entries of ``result`` that are dicts of columns into ``Table``s (in place)."""
    for name in names:
        if isinstance(result.get(name), dict):
            result[name] = Table(result[name])
