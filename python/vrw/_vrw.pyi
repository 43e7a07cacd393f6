"""Type stubs of the compiled extension ``vrw._vrw`` (re-exported by ``vrw``)."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt
from typing_extensions import TypedDict, Unpack, final

__version__: str
__all__ = [
    "ConfigError",
    "Params",
    "WalkError",
    "__version__",
    "_params_from_dict",
    "_walker_params",
    "animate",
    "basin",
    "continue_family",
    "find_gait",
    "map",
    "orbit",
    "linspace",
    "simulate",
    "sweep",
]

Value = Union[float, int, bool, str]
Section = Union[Tuple[float, float, float], Tuple[float, float, float, float], Sequence[float]]
# A job's progress report: called as ``progress(done, total)`` on the calling thread as points finish.
Progress = Callable[[int, int], object]

class GaitOptions(TypedDict, total=False):
    """Search settings (the library's ``GaitOptions``; ``gait.json``'s ``options``), as keyword arguments."""

    transient_steps: int  # steps walked before Newton's method starts (default 30; 0 to 100000)
    max_iterations: int  # Newton iterations allowed (default 20; 1 to 1000)
    tolerance: float  # convergence: max |P(s) - s| below this (default 1e-10; 1e-13 to 1e-6)
    fd_step: float  # relative finite-difference step where differences are used (default 1e-4; 1e-6 to 1e-2)
    refine_jacobian: bool  # error estimate of the exact Jacobian (default True)
    parameter: Optional[str]  # also dP/dp of the gait for this key (``dP_dparam``; default None)

class ConfigError(ValueError):
    """Invalid parameters (unknown key, wrong type, broken rule, bad TOML file), or a search setting, a sweep
    value or a count out of its range; the command line's message, naming the keyword."""

class WalkError(RuntimeError):
    """A walk that cannot start (e.g. an invalid initial section state); the command line's message."""

def _params_from_dict(keys: Dict[str, Value]) -> "Params":
    """``Params(**keys)``: how a pickled ``Params`` is rebuilt."""

def _walker_params(model: str, text: Optional[str], keys: Dict[str, Value]) -> "Params":
    """``Params(model=model, **keys)``, a description read from its ``text``: how a pickled walker's
    ``Params`` is rebuilt."""

@final
class Params:
    """The model's parameters and the solver's settings: every key of a vrw TOML file, or another walker's
    parameters.

    ``Params(viscosity=37)`` starts from the defaults (the paper's Table 1, c = 50 N s/m) and applies each
    keyword as a TOML key, validated as the command line does; an unknown key or a bad value raises
    ``ConfigError`` (a ``ValueError``) with the command line's message. ``Params(model="compass",
    slope=0.05)`` (``"simplest"``, ``"compass"``, ``"telescopic"`` or a description's path, ``.toml``) holds
    another walker's parameters, validated as ``vrw --model NAME --set key=value`` does. Immutable,
    comparable, picklable.
    """

    def __new__(cls, *, model: Optional[str] = None, **keys: Value) -> "Params": ...
    @staticmethod
    def from_toml(path: Union[str, "PathLike[str]"], model: Optional[str] = None) -> "Params":
        """Read a flat TOML file of parameters (as ``vrw --config FILE``, with ``--model model``)."""
    @property
    def model(self) -> str:
        """``"vrw"`` (the wheel), a built-in walker's name, or a description's path as given."""
    def to_dict(self) -> Dict[str, Value]:
        """Every key and its value, as a TOML file (or ``summary.json``'s ``config``) holds them; a walker's
        parameters."""
    def replace(self, **keys: Value) -> "Params":
        """A copy with the given keys changed (validated as in the constructor)."""
    def __getitem__(self, key: str, /) -> Value: ...
    def __reduce__(self) -> Tuple[Callable[..., "Params"], Tuple[Any, ...]]:
        """Pickle as ``Params(**to_dict())`` (a walker's with its model and description), for every pickle
        protocol."""
    @staticmethod
    def numeric_keys() -> List[str]:
        """The wheel's keys holding a real number (what a sweep or a grid can vary)."""
    def parameter_keys(self) -> List[str]:
        """The keys this model's sweeps, continuations and orbit diagrams can vary: the wheel's
        ``numeric_keys()``, or a walker's parameters."""
    def __eq__(self, other: object, /) -> bool: ...

def simulate(
    params: Params,
    steps: int = 20,
    initial: Optional[Section] = None,
    trajectory: bool = True,
    sample_dt: float = 0.005,
) -> Dict[str, Any]:
    """Walk ``steps`` steps from ``initial`` (``vrw simulate``).

    ``initial`` is the Poincare-section state ``(L2, thetadot, L2dot)``; ``None`` is the command line's
    default, derived from the parameters (``(0.72, 1.0, 0.0)`` for Table 1, the rigid gait with
    ``rigid_legs``; see ``docs/model.md`` section 6). Returns the fields of
    ``summary.json`` (``status``: ``completed`` or the failure kind, ``message``, ``steps_completed``,
    ``end_time``, ``config``, ...) with ``steps`` replaced by a dict of numpy arrays keyed like the columns
    of ``steps.csv`` and ``trajectory`` a dict of numpy arrays keyed like ``trajectory.csv`` (``None`` if
    ``trajectory=False``). A walk that stops early is a status, not an exception; an invalid initial state
    raises ``WalkError``. Another walker's (``Params(model=...)``): ``vrw simulate --model``'s files, the
    tables named by the model's coordinates, ``initial`` its section's coordinates.
    """

def find_gait(
    params: Params,
    initial: Optional[Section] = None,
    **options: Unpack[GaitOptions],
) -> Dict[str, Any]:
    """Find the gait (``vrw gait``): the fields of ``gait.json``.

    ``status`` is ``found`` or why no gait was found (``message`` says it in words, as the command line
    does); a found gait adds its fields (``section``, ``lambda_I4``, ``lambda_2_plus``, ..., ``stable``),
    with ``floquet_multipliers`` as a complex numpy array and ``jacobian`` as a 2-D numpy array. Options
    not given take the library's defaults (see ``GaitOptions``). Another walker's (``Params(model=...)``):
    ``vrw gait --model``'s ``gait.json`` with its gait's fields at the top (``section`` by the model's
    coordinates, ``period``, ``lambda_I4``, ``impact_loss``, ``energy_drift``, ``stable``, ...); options
    ``transient_steps`` and ``parameter`` only.
    """

def sweep(
    params: Params,
    param: str,
    values: Union[Sequence[float], npt.NDArray[np.float64]],
    *,
    initial: Optional[Section] = None,
    progress: Optional[Progress] = None,
    **options: Unpack[GaitOptions],
) -> Dict[str, Any]:
    """Sweep ``param`` over ``values`` with continuation and locate the thresholds (``vrw sweep``).

    Returns ``{"param", "sweep", "thresholds", "gaits_found", "seconds"}``: ``sweep`` holds the columns
    of ``sweep.csv`` as numpy arrays, of the dtypes ``pandas.read_csv`` gives the file (reals as float64 with
    NaN, flags as bool with False and words as strings with '' where no gait was found; counts as int64, or
    float64 with NaN if a cell is empty; a column with no value at all as float64 NaN), ``thresholds`` the entries of
    ``thresholds.json`` as dicts. Options default to the command line's sweep settings (one central
    difference for the final Jacobian). ``vrw.linspace`` gives the command line's evenly spaced values.
    Another walker's (``Params(model=...)``): ``vrw sweep --model``'s ``thresholds.json`` fields and
    ``sweep``, at these values; no options, no ``progress`` yet.
    """

def linspace(start: float, stop: float, points: int) -> List[float]:
    """The values ``vrw sweep --from START --to STOP --points POINTS`` visits (bit for bit); 2 to 100000
    points, else ``ConfigError``."""

def continue_family(
    params: Params,
    param: str = "viscosity",
    *,
    start: Optional[float] = None,
    range: Optional[Tuple[float, float]] = None,
    initial: Optional[Section] = None,
    period: Optional[int] = None,
    max_points: int = 300,
    max_step: float = 0.1,
    switch: bool = True,
    two_param: Optional[Tuple[str, float, float]] = None,
    extremum: Optional[List[str]] = None,
) -> Dict[str, Any]:
    """Follow the gait family through the gait at ``start`` by pseudo-arclength continuation (``vrw continue``,
    without the figure): the fields of ``special_points.json`` and ``branch``, the columns of ``branch.csv``.
    ``range`` is ``(from, to)``, default ``(1, 300)``; ``two_param`` ``(name, from, to)`` also follows every
    border collision's curve in that second parameter (``curves`` in
    ``special_points.json``'s form, and ``curve_points``, the columns of ``curves.csv``); ``extremum`` (names of
    monitored quantities, ``--extremum``) locates their extrema along every family, special points ``EX`` with
    an ``extremum`` record, and gives ``monitored``, the columns of ``monitored.csv``. Another walker's
    (``Params(model=...)``): ``vrw continue --model``'s, its start's family only (no ``initial``, ``period``,
    ``two_param``, ``extremum``)."""

def map(
    params: Params,
    *,
    x: str = "viscosity",
    y: str = "stiffness",
    x_range: Optional[Tuple[float, float]] = None,
    y_range: Optional[Tuple[float, float]] = None,
    nx: int = 21,
    ny: int = 21,
    curves: bool = True,
    curve_columns: int = 25,
    curve_method: str = "continuation",
    second_route: bool = False,
    initial: Optional[Section] = None,
    rows: Optional[Tuple[int, int]] = None,
    progress: Optional[Progress] = None,
) -> Dict[str, Any]:
    """The gait over a grid of two parameters and the threshold curves (``vrw map``, without the figure): the
    fields of ``curves.json`` and ``map``, the columns of ``map.csv``. ``x_range`` and ``y_range`` default to
    the command line's ``(1, 300)`` and ``(300, 1500)``; ``curve_method`` is ``"continuation"`` or
    ``"crossings"``. ``rows=(start, end)`` computes only those rows' gaits (with ``curves=False``), each point
    as the whole map has it; ``progress(done, total)`` is called on this thread as points finish. Ctrl-C
    while the curves are traced raises ``KeyboardInterrupt`` with the complete gaits as its ``partial`` (this
    result without curves, with ``interrupted``). Another walker's (``Params(model=...)``): ``vrw map
    --model``'s ``map.json`` fields and ``map``, ``x`` and ``y`` two of its parameters, ``curves`` its changes
    of stability bisected along the rows (``thresholds``; Ctrl-C while they are bisected hands the gaits on as
    ``partial``), without ``curve_columns``, ``curve_method``, ``second_route`` and ``rows``."""

def orbit(
    params: Params,
    param: str = "viscosity",
    *,
    range: Optional[Tuple[float, float]] = None,
    points: int = 300,
    transient: int = 32,
    steps: int = 64,
    initial: Optional[Section] = None,
    branch: bool = True,
    progress: Optional[Progress] = None,
    part: Optional[Union[str, Tuple[str, int, Optional[Section]]]] = None,
) -> Dict[str, Any]:
    """The orbit diagram along ``param`` (``vrw orbit``, without the figure): the fields of ``orbit.json``,
    ``orbit`` (the columns of ``orbit.csv``) and, with ``branch``, ``branch`` (the columns of ``branch.csv``).
    ``range`` defaults to the command line's ``(1, 150)``. ``progress(done, total)`` is called on this thread as
    values finish; ``part`` (``"coarse"``, ``("fill", k, left)`` or ``"branch"``) computes one part of the job,
    for ``vrw.grid.orbit_grid``, and adds ``ends`` and ``column_rows``. Another walker's
    (``Params(model=...)``): ``vrw orbit --model``'s, without ``progress`` and ``part`` yet."""

def basin(
    params: Params,
    *,
    x: Optional[str] = None,
    y: Optional[str] = None,
    x_range: Optional[Tuple[float, float]] = None,
    y_range: Optional[Tuple[float, float]] = None,
    nx: int = 61,
    ny: int = 61,
    max_steps: int = 100,
    tolerance: float = 1e-3,
    initial: Optional[Section] = None,
    rows: Optional[Tuple[int, int]] = None,
    progress: Optional[Progress] = None,
) -> Dict[str, Any]:
    """The basin of the gait on a slice of the section (``vrw basin``, without the figure).

    Returns the fields of ``basin.json`` (``spec``, ``gait``, ``outcomes``, ...) and ``points``: the columns
    of ``basin.csv`` as numpy arrays, one row per grid point, row by row. The options are the command line's
    (``x``, ``y``: ``"L2"``, ``"thetadot"``, ``"L2dot"``, default ``"L2"`` and ``"thetadot"``; ``x_range``,
    ``y_range``: ``(from, to)``, default the command line's), validated as it validates them.
    ``rows=(start, end)`` computes only those grid rows, each point as the whole basin has it;
    ``progress(done, total)`` is called on this thread as points finish. Ctrl-C raises ``KeyboardInterrupt``
    within about a second. Another walker's (``Params(model=...)``): ``vrw basin --model``'s ``basin.json``
    fields and ``points``, ``x`` and ``y`` two of its section's coordinates (default its first and second),
    without ``rows``.
    """

def animate(
    params: Params,
    steps: int = 20,
    initial: Optional[Section] = None,
    sample_dt: float = 0.005,
    *,
    fps: int = 25,
    speed: float = 1.0,
    from_: Optional[float] = None,
    to: Optional[float] = None,
    width: int = 640,
    height: int = 360,
    horizontal: bool = False,
    still: Optional[float] = None,
) -> bytes:
    """Walk ``steps`` steps from ``initial`` as ``simulate`` does and draw the walk as ``vrw animate`` does:
    the bytes of the GIF ``walk.gif`` it writes for the directory of ``vrw simulate``, or with ``still`` (a
    time [s]) those of the PNG of that frame (``vrw animate --still``). The options are the command line's
    (``from_`` is ``--from``), with its defaults and ranges; a bad one, more than 90000 frames or a window
    outside the walk raises ``ConfigError`` with the command line's message. Another walker's
    (``Params(model=...)``): its ``vrw simulate --model`` walk (``initial`` its section's coordinates) drawn as
    ``vrw animate`` draws that run. See ``vrw.animate``."""
