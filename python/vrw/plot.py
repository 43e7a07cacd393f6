"""The command line's figures drawn with matplotlib, on axes you can restyle and combine.

Each function takes the result of a job, draws what the command line's figure shows on ``ax`` (an ``Axes``,
or a sequence of Axes for a figure of several panels) or, without ``ax``, on a new figure, and returns the
axes it drew on (an ``Axes``, or a numpy array of them):

- ``fig2(sweep)``: Fig. 2 of the paper from ``vrw.sweep`` (``vrw sweep``'s ``fig2.png``);
- ``run(run)``: the walk against time from ``vrw.simulate`` (``vrw plot``'s ``run.png``);
- ``steps(run)``: indicators, period and energy audit per step, Leg 2 over the last step (``steps.png``);
- ``map(result, column)``: a column of ``vrw.map`` over both parameters with the threshold curves (a panel
  of ``vrw map``'s ``map.png``);
- ``orbit(result)``: the orbit diagram of ``vrw.orbit`` (``vrw orbit``'s ``orbit.png``);
- ``basin(result)``: the basin of ``vrw.basin`` (``vrw basin``'s ``basin.png``).

Other keyword options go to the call that draws the data (``plot``, or ``pcolormesh`` for ``map`` and
``basin``). matplotlib is optional (``pip install matplotlib``) and imported when a function is called;
nothing here selects a backend or shows a figure::

    import vrw, vrw.plot
    axes = vrw.plot.fig2(vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(1, 300, 60)))
    axes[0].figure.savefig("fig2.png")
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

__all__ = ["fig2", "sweep", "run", "steps", "map", "orbit", "basin"]

AxesArg = Union["Axes", Sequence["Axes"], None]
Panels = List[Tuple[str, List[Tuple[str, str]]]]  # y label, series (column, colour)

# The command line's palette (src/output/style.rs: Okabe-Ito) and greys.
BLACK, BLUE, VERMILLION, GREEN = "#000000", "#0072B2", "#D55E00", "#009E73"
PURPLE, ORANGE, MARK, FRAME = "#CC79A7", "#E69F00", "#5A5A5A", "#969696"
NO_GAIT, NO_GAIT_BAND, FAILED = "#C8C8C8", "#E4E4E4", "#EBEBEB"

# Axis labels are "symbol [unit]" (src/app/mod.rs axis_label), legends use the name or the symbol.
_SYMBOLS = {
    "viscosity": "c", "stiffness": "k", "slope": "φ", "hub_mass": "mH", "leg_mass": "m", "theta": "θ",
    "thetadot": "dθ/dt", "L2dot": "dL2/dt", "period": "T", "max_floquet": "max |μ|",
    "lambda_I4": r"$\lambda_{I4}$", "lambda_2_plus": r"$\lambda_2^+$", "lambda_4_plus": r"$\lambda_4^+$"}
_UNITS = {
    "viscosity": "N s/m", "stiffness": "N/m", "slope": "rad", "hub_mass": "kg", "leg_mass": "kg",
    "hub_inertia": "kg m²", "gravity": "m/s²", "leg_mass_offset": "m", "stopper_length": "m",
    "spring_natural_length": "m", "L2": "m", "thetadot": "rad/s", "L2dot": "m/s", "theta": "rad",
    "lambda_I4": "N s", "lambda_2_plus": "N", "lambda_4_plus": "N", "period": "s", "speed": "m/s",
    "step_length": "m", "dls_duration": "s"}
_NAMES = {
    "period": "period", "max_floquet": "largest |multiplier|", "dls_duration": "DLS duration",
    "L1": "$L_1$ (Leg 1)", "L2": "$L_2$ (Leg 2)", "lambda_1": r"$\lambda_1$ (Leg 1)",
    "lambda_2": r"$\lambda_2$ (Leg 1)", "lambda_3": r"$\lambda_3$ (Leg 2)",
    "lambda_4": r"$\lambda_4$ (Leg 2)", "energy_loss": "loss of T + V", "damper_loss": "damper",
    "impact_loss": "impacts", "stopper_loss": "stoppers", "energy_residual": "residual"}
# Thresholds and curves: text, colour, dashed (src/output/map_plot.rs curve_style).
_THRESHOLDS = {
    "existence_end": ("end of the gait", BLACK, False), "gait_lost": ("gait lost", BLACK, False),
    "gait_found": ("gait found", BLACK, False),
    "lambda_4_plus = 0": (r"$\lambda_4^+ = 0$", VERMILLION, False),
    "lambda_2_plus = 0": (r"$\lambda_2^+ = 0$", BLUE, False),
    "lambda_I4 = 0": (r"$\lambda_{I4} = 0$", GREEN, False),
    "stability_lost": ("stability lost", PURPLE, True),
    "stability_regained": ("stability regained", PURPLE, True),
    "period_doubling": ("period doubling", PURPLE, True), "branch_switch": ("branch switch", ORANGE, True),
    "fold": ("fold", BLACK, True)}
_UNCONFIRMED = ("end, unconfirmed", MARK, True)

# Panels: y label, (reference line,) series: column, colour(, marker) (src/output/plot/, run_plot.rs,
# steps_plot.rs).
_FIG2: List[Tuple[str, float, List[Tuple[str, str, str]]]] = [
    (r"$\lambda_{I4}$ [N s]", 0.0, [("lambda_I4", BLACK, "o")]),
    (r"$\lambda$ [N]", 0.0, [("lambda_2_plus", BLUE, "o"), ("lambda_4_plus", VERMILLION, "^")]),
    ("T [s]", 0.0, [("period", BLACK, "o")]), ("max |μ|", 1.0, [("max_floquet", BLUE, "o")])]
_RUN: Panels = [
    ("θ of Leg 1 [rad]", [("theta", BLUE)]), ("dθ/dt [rad/s]", [("thetadot", BLUE)]),
    ("leg length [m]", [("L1", BLUE), ("L2", VERMILLION)]),
    ("normal force [N]", [("lambda_2", BLUE), ("lambda_4", VERMILLION)]),
    ("tangential force [N]", [("lambda_1", BLUE), ("lambda_3", VERMILLION)])]
_STEPS: Panels = [
    (r"$\lambda_{I4}$ [N s]", [("lambda_I4", BLACK)]),
    (r"$\lambda^+$ [N]", [("lambda_2_plus", BLUE), ("lambda_4_plus", VERMILLION)]),
    ("time [s]", [("period", BLACK), ("dls_duration", BLUE)]),
    ("energy [J]", [("energy_loss", BLACK), ("damper_loss", BLUE), ("impact_loss", VERMILLION),
                    ("stopper_loss", PURPLE)]), ("audit residual [J]", [("energy_residual", BLACK)])]
_PHASES = [("DLS", "#DEEBF7"), ("a tip slides", "#FDD0A2"), ("SLS", "#FFF7BC"),
           ("rear support", "#DADAEB"), ("flight", "#FCBBA1")]
_TIPS = [("tip on ground, no slip", GREEN), ("tip sliding", ORANGE), ("tip in the air", MARK)]
# Impact branches on the map (the palette lightened), basin outcomes (src/output/basin_plot.rs).
_BRANCHES = {"DLS": "#73CAB2", "SLS": "#F1CA73", "SLS_B3": "#E3B5CF", "BOUNCE": "#73B1D5",
             "REAR_AIRBORNE": "#F0E442"}
_OUTCOMES = {"gait": GREEN, "other": BLUE, "rolled_back": ORANGE, "fell": VERMILLION, "chatter": PURPLE,
             "undecided": "#C8C8C8", "invalid_start": "#FFFFFF", "stalled": "#56B4E9",
             "rear_leg_in_contact": "#F0E442", "rear_leg_not_locked": "#785028"}
_OUTCOME_TEXT = {"gait": "reaches the gait", "other": "settles on another gait", "undecided": "undecided",
                 "invalid_start": "not a section state"}
_OUTCOME_ORDER = {"gait": 0, "other": 1, "undecided": 3, "invalid_start": 4}
_ABOVE: Dict[str, Any] = {"loc": "lower left", "bbox_to_anchor": (0, 1.01), "frameon": False}  # over the axes


def _label(key: str) -> str:
    """Axis label of a parameter or column: symbol and unit, e.g. ``c [N s/m]``; the key if unknown."""
    symbol, unit = _SYMBOLS.get(key, key), _UNITS.get(key)
    return f"{symbol} [{unit}]" if unit else symbol


def _name(column: str) -> str:
    return _NAMES.get(column, _SYMBOLS.get(column, column))


def _axes(ax: AxesArg, n: int, figsize: Tuple[float, float], side: bool = False) -> np.ndarray:
    """The ``n`` axes to draw on, as an array: ``ax`` (an Axes when ``n`` is 1, else ``n`` Axes) checked, or a
    new figure's, stacked on a shared x axis (with ``side``, the last one right of the others, as tall)."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("vrw.plot draws with matplotlib: pip install matplotlib") from e
    if ax is None:
        fig = plt.figure(figsize=figsize, layout="constrained")
        rows = n - int(side)
        grid = fig.add_gridspec(rows, 1 + int(side), width_ratios=(1.4, 1) if side else None)
        axes: List[Any] = []
        for i in range(rows):
            axes.append(fig.add_subplot(grid[i, 0], sharex=axes[0] if axes else None))
            axes[-1].tick_params(labelbottom=i == rows - 1)
        if side:
            axes.append(fig.add_subplot(grid[:, 1]))
    else:
        axes = [ax] if hasattr(ax, "plot") else list(np.ravel(np.asarray(ax, dtype=object)))
        if len(axes) != n:
            raise ValueError(f"this figure has {n} panel(s): pass {n} Axes, not {len(axes)}")
    out = np.empty(n, dtype=object)
    out[:] = axes
    return out


def _legend(ax: Any, handles: Optional[List[Any]] = None, labels: Optional[List[str]] = None,
            **options: Any) -> None:
    """A legend (of ``handles``, else of the labelled artists) right of ``ax``, or where ``options`` say."""
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    if handles:
        where = {"loc": "upper left", "bbox_to_anchor": (1.01, 1), "fontsize": "small", **options}
        ax.legend(handles, labels or [h.get_label() for h in handles], **where)


def _spans(ax: Any, spans: Sequence[Tuple[float, float]], color: str, label: str) -> None:
    """Shade the x intervals ``spans`` over the height of ``ax`` (one collection, under the data)."""
    from matplotlib.collections import PolyCollection

    if len(spans):
        ax.add_collection(PolyCollection([[(a, 0), (b, 0), (b, 1), (a, 1)] for a, b in spans], label=label,
                                         transform=ax.get_xaxis_transform(), facecolors=color,
                                         edgecolors="none", zorder=0), autolim=False)


def _vlines(ax: Any, xs: Sequence[float]) -> None:
    """Dashed grey vertical lines at ``xs`` over the height of ``ax`` (thresholds, touchdowns)."""
    from matplotlib.collections import LineCollection

    if len(xs):
        ax.add_collection(LineCollection([[(x, 0), (x, 1)] for x in xs], transform=ax.get_xaxis_transform(),
                                         colors=MARK, linestyles="--", linewidths=1), autolim=False)


def _panels(axes: np.ndarray, x: Any, table: Mapping[str, Any], panels: Panels, **options: Any) -> None:
    """Each panel's columns of ``table`` against ``x`` on its axes, with its y label."""
    for ax, (y_label, series) in zip(axes, panels):
        for column, color in series:
            ax.plot(x, table[column], **{"color": color, **options}, label=_name(column))
        ax.set_ylabel(y_label)


def _categories(ax: Any, xs: Any, ys: Any, grid: np.ndarray, kinds: List[Tuple[str, str, str]],
                **options: Any) -> List[Any]:
    """Colour the cells of ``grid`` (words, ``len(ys)`` by ``len(xs)``) by ``kinds`` (value, label, colour);
    returns their legend patches."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    codes = np.zeros(grid.shape)
    for i, (value, _, _) in enumerate(kinds):
        codes[grid == value] = i
    ax.pcolormesh(xs, ys, codes, shading="nearest", cmap=ListedColormap([c for _, _, c in kinds]),
                  vmin=-0.5, vmax=len(kinds) - 0.5, **options)
    return [Patch(facecolor=c, edgecolor=FRAME, label=label) for _, label, c in kinds]


def _no_gait(x: np.ndarray, gait: np.ndarray, cuts: List[float]) -> List[Tuple[float, float]]:
    """The x intervals without a gait (src/app/sweep.rs no_gait_spans): each run of points without one, from
    the threshold (else the midpoint) between it and the points with a gait beside it, or the sweep's end."""
    def edge(a: float, b: float) -> float:
        return next((v for v in cuts if min(a, b) <= v <= max(a, b)), 0.5 * (a + b))

    spans, i, n = [], 0, len(x)
    while i < n:
        j = i
        while j < n and not gait[j]:
            j += 1
        if j > i:
            spans.append((edge(x[i - 1], x[i]) if i else x[0], edge(x[j - 1], x[j]) if j < n else x[-1]))
        i = j + 1
    return spans


def _threshold_text(t: Mapping[str, Any], key: str) -> str:
    """A threshold's label, e.g. ``gait lost: c = 135.49`` (src/app/sweep.rs write_fig2)."""
    text = _THRESHOLDS.get(t["name"], _UNCONFIRMED)[0]
    if t["name"] == "gait_found" and "found again" in (t.get("detail") or ""):
        text = "gait found again"
    return f"{text}: {_SYMBOLS.get(key, key)} = {t['value']:.2f}"


def fig2(sweep: Mapping[str, Any], ax: AxesArg = None, panels: int = 2, **options: Any) -> np.ndarray:
    """Fig. 2 of the paper from a ``SweepResult`` (``vrw sweep``'s ``fig2.png``): (a) lambda_I4 [N s] and (b)
    lambda_2+, lambda_4+ [N] against the swept parameter; with ``panels=4``, as the command line, also (c)
    the period and (d) the largest Floquet multiplier. Hollow markers: scuffing of Leg 2; lines never join two
    gait families; grey: no gait; each threshold a labelled dashed line. ``ax``: ``panels`` Axes. Returns the
    array of axes."""
    if panels not in (2, 4):
        raise ValueError(f"panels is 2 (the paper's Fig. 2) or 4 (with period and multipliers), not {panels}")
    _wheel_only(sweep, "fig2", "vrw.plot.sweep draws its lambda_I4, period and multipliers")
    axes = _axes(ax, panels, (8, 1.2 + 2.6 * panels))
    table, key = sweep["sweep"], sweep["param"]
    order = np.argsort(np.asarray(table[key], dtype=float), kind="stable")

    def column(name: str) -> np.ndarray:
        return np.asarray(table[name], dtype=float)[order]

    x, family, scuffing = column(key), column("family"), column("scuffing") > 0
    cuts = [t["value"] for t in sweep["thresholds"] if isinstance(t.get("value"), (int, float))
            and math.isfinite(t["value"])]
    families = [family == f for f in np.unique(family[np.isfinite(family)])] or [np.isnan(family)]
    for axis, (y_label, reference, series) in zip(axes, _FIG2[:panels]):
        for name, color, marker in series:
            for k, members in enumerate(families):  # a line per family, broken where there is no value
                line = axis.plot(x, np.where(members, column(name), np.nan),
                                 **{"color": color, "marker": marker, "ms": 5, **options},
                                 label=_name(name) if k == 0 else "_nolegend_")[0]
                line.sticky_edges.y.append(0.0)  # no margin below zero when no value is negative
        for name, color, marker in series:
            axis.plot(x, np.where(scuffing, column(name), np.nan),
                      **{"marker": marker, "ms": 5, **options, "ls": "", "mfc": "white", "mec": color},
                      label="scuffing of Leg 2" if scuffing.any() and name == series[0][0] else "_nolegend_")
        if not any(np.isfinite(column(name)).any() for name, _, _ in series):
            axis.text(0.5, 0.5, "not defined for these gaits (e.g. rigid legs)", transform=axis.transAxes,
                      ha="center")
        _spans(axis, _no_gait(x, np.isfinite(column("period")), cuts), NO_GAIT_BAND, "no gait")
        axis.axhline(reference, color="black", linewidth=1)
        _vlines(axis, cuts)
        axis.set_ylabel(y_label)
        _legend(axis)
    for t in sweep["thresholds"]:
        if t["value"] in cuts:
            axes[0].annotate(_threshold_text(t, key), (t["value"], 1), xycoords=("data", "axes fraction"),
                             xytext=(2, -4), textcoords="offset points", rotation=90, ha="left", va="top",
                             fontsize="small")
    axes[-1].set_xlim(x.min(), x.max())
    axes[-1].set_xlabel(_label(key))
    return axes


def _wheel_only(result: Mapping[str, Any], figure: str, instead: str) -> None:
    """A ``ValueError`` naming the model if ``result`` is another walker's (``vrw.Params(model=...)``), whose
    tables lack the wheel's columns this figure draws; ``instead`` says what draws it."""
    model = result.get("model")
    if model is not None and model != "vrw":
        raise ValueError(f"vrw.plot.{figure} draws the wheel's results; the model `{model}` has other columns: "
                         f"{instead}")


def sweep(result: Mapping[str, Any], ax: AxesArg = None, **options: Any) -> np.ndarray:
    """A sweep of any model (``vrw.sweep``, the wheel's or another walker's) against its parameter: lambda_I4,
    the step's period and the largest modulus of the Floquet multipliers (1 drawn: the stability border),
    black where the gait is stable, vermillion where not; each threshold a dashed line, values without a gait
    shaded. ``ax``: 3 Axes. Returns their array."""
    table, key = result["sweep"], result["param"]
    order = np.argsort(np.asarray(table[key], dtype=float), kind="stable")
    x = np.asarray(table[key], dtype=float)[order]
    stable = np.asarray(table["stability"])[order] == "stable"
    cuts = [t["value"] for t in result["thresholds"] if isinstance(t.get("value"), (int, float))
            and math.isfinite(t["value"])]
    axes = _axes(ax, 3, (8, 8))
    for axis, (name, reference) in zip(axes, [("lambda_I4", 0.0), ("period", None), ("max_floquet", 1.0)]):
        y = np.asarray(table[name], dtype=float)[order]
        axis.plot(x, y, **{"color": MARK, "lw": 1, **options}, label="_nolegend_")
        for members, color, label in ((stable, BLACK, "stable"), (~stable, VERMILLION, "unstable")):
            axis.plot(x, np.where(members, y, np.nan), **{"ls": "", "marker": "o", "ms": 4, "color": color,
                                                          **options}, label=label)
        if reference is not None:
            axis.axhline(reference, color="black", linewidth=1)
        _spans(axis, _no_gait(x, np.isfinite(np.asarray(table["period"], dtype=float)[order]), cuts),
               NO_GAIT_BAND, "no gait")
        _vlines(axis, cuts)
        axis.set_ylabel(_label(name) if name != "max_floquet" else "max |μ|")
    _legend(axes[0])
    axes[-1].set_xlim(x.min(), x.max())
    axes[-1].set_xlabel(_label(key))
    return axes


def _walker_run(run: Mapping[str, Any], ax: AxesArg, **options: Any) -> np.ndarray:
    """``vrw plot``'s run figure of another walker (src/output/walker_plot.rs): each coordinate against time,
    then the energies T, V and T + V; every heel strike dashed, the curves broken there."""
    trajectory = run["trajectory"]
    coordinates = list(run["coordinates"])
    axes = _axes(ax, len(coordinates) + 1, (10, 2.2 * (len(coordinates) + 1)))
    cut = np.flatnonzero(np.diff(trajectory["step"]) != 0) + 1  # where the legs exchange roles
    broken = {c: np.insert(np.asarray(v, dtype=float), cut, np.nan) for c, v in trajectory.items()}
    panels: Panels = [(c, [(c, BLUE)]) for c in coordinates]
    panels.append(("energy", [("kinetic", BLUE), ("potential", VERMILLION), ("energy", BLACK)]))
    _panels(axes, broken["time"], broken, panels, **options)
    for axis in axes:
        _vlines(axis, np.asarray(run["steps"]["time"])[1:])
    _legend(axes[-1])
    t = np.asarray(trajectory["time"], dtype=float)
    axes[-1].set_xlim(t[0], t[-1])
    axes[-1].set_xlabel("time")
    axes[0].set_title(f"{run['model']}: {run['steps_completed']} steps")
    return axes


def run(run: Mapping[str, Any], ax: AxesArg = None, **options: Any) -> np.ndarray:
    """The run figure of ``vrw plot`` (``run.png``) from a ``Run`` with its trajectory: against time, theta of
    Leg 1, its rate, the leg lengths with the stopper length L0 dashed, the normal forces lambda_2, lambda_4
    and the tangential ones lambda_1, lambda_3 (Leg 1 blue, Leg 2 vermillion), the background shaded by
    phase, every touchdown dashed; curves break where the legs are re-indexed. ``ax``: 5 Axes. Returns their
    array."""
    trajectory = run.get("trajectory")
    if not trajectory:
        raise ValueError("the run has no trajectory: simulate with trajectory=True")
    if run.get("model", "vrw") != "vrw":
        return _walker_run(run, ax, **options)
    axes = _axes(ax, 5, (10, 12))
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    cut = np.flatnonzero(np.diff(trajectory["leg1"]) != 0) + 1  # where the legs are re-indexed
    broken = {c: np.insert(np.asarray(v, dtype=float), cut, np.nan) for c, v in trajectory.items()}
    _panels(axes, broken["time"], broken, _RUN, **options)
    l0 = run["config"]["stopper_length"]
    axes[2].axhline(l0, color=MARK, linestyle="--", label=f"$L_0$ = {l0:g} m")
    min_length = run["config"].get("min_length", 0.0)  # the compression stop, where there is one
    if min_length > 0:
        axes[2].axhline(min_length, color=MARK, linestyle="--", label=f"min_length = {min_length:g} m")
    c1, c2, s1, s2 = (np.asarray(trajectory[c]) > 0 for c in ("contact1", "contact2", "slide1", "slide2"))
    phase = np.select([(c1 & s1) | (c2 & s2), c1 & c2, c1, c2], [1, 0, 2, 3], 4)[:-1]
    change = np.flatnonzero(np.diff(phase) != 0) + 1
    t = np.asarray(trajectory["time"], dtype=float)
    bands = list(zip(np.r_[0, change], np.r_[change, len(phase)]))  # sample k's phase lasts to sample k + 1
    for axis in axes:
        for k, (_, color) in enumerate(_PHASES):
            _spans(axis, [(t[a], t[b]) for a, b in bands if phase[a] == k], color, "_nolegend_")
        _vlines(axis, run["steps"]["time"])
        _legend(axis)
    # The phases and the touchdowns over the top panel, as its legend (constrained layout makes room for it).
    if axes[0].get_legend():
        axes[0].add_artist(axes[0].get_legend())
    shading = [Patch(facecolor=c, edgecolor=FRAME, label=text) for k, (text, c) in enumerate(_PHASES)
               if (phase == k).any()] + [Line2D([], [], color=MARK, ls="--", lw=1, label="touchdown")]
    _legend(axes[0], shading, ncol=len(shading), title="phases:", alignment="left", **_ABOVE)
    axes[-1].set_xlim(t[0], t[-1])
    axes[-1].set_xlabel("time t [s]")
    return axes


def steps(run: Mapping[str, Any], ax: AxesArg = None, **options: Any) -> np.ndarray:
    """The steps figure of ``vrw plot`` (``steps.png``) from a ``Run``: against the step number, lambda_I4,
    lambda_2+ and lambda_4+, the period and the DLS duration, the energy audit and its residual (five stacked
    panels); and the phase portrait of Leg 2 over the last step (L2 against dL2/dt coloured by the state of
    its tip, L0 dashed; it needs the trajectory). ``ax``: 6 Axes, the portrait last. Returns their array."""
    table = run["steps"]
    if not len(table["step"]):
        raise ValueError("the run has no step")
    _wheel_only(run, "steps", "vrw.plot.run draws its coordinates and energies; its steps table holds "
                "lambda_I4, period, stride and the energy audit per step")
    axes = _axes(ax, 6, (14, 8), side=True)
    from matplotlib.collections import LineCollection
    from matplotlib.ticker import MaxNLocator

    _panels(axes[:5], table["step"], table, _STEPS, **{"marker": "o", "ms": 4, **options})
    for axis in axes[:5]:
        _legend(axis)
    axes[4].xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[4].set_xlabel("step number")
    portrait, trajectory = axes[5], run.get("trajectory")
    if trajectory:  # from the last touchdown to the end or the next re-indexing
        time, leg1 = np.asarray(trajectory["time"]), np.asarray(trajectory["leg1"])
        start = min(int(np.searchsorted(time, table["time"][-1])), len(time) - 1)
        end = start + int(np.argmax(np.r_[leg1[start:] != leg1[start], True]))
        last = {c: np.asarray(trajectory[c][start:end]) for c in ("L2", "L2dot", "contact2", "slide2")}
        tip = np.where(last["contact2"] == 0, 2, last["slide2"] != 0)[:-1]
        points = np.column_stack([last["L2"], last["L2dot"]])
        for k, (label, color) in enumerate(_TIPS):
            if (tip == k).any():
                segments = np.stack([points[:-1], points[1:]], axis=1)[tip == k]
                portrait.add_collection(LineCollection(segments, colors=color, label=label))
        portrait.autoscale_view()
        portrait.set_title(f"Leg 2, step {table['step'][-1]}, t = {time[start]:.3f} .. {time[end - 1]:.3f} s")
    l0 = run["config"]["stopper_length"]
    portrait.axvline(l0, color=MARK, linestyle="--", label=f"$L_0$ = {l0:g} m")
    portrait.set_xlabel("$L_2$ [m]")
    portrait.set_ylabel("d$L_2$/dt [m/s]")
    _legend(portrait, loc="best", bbox_to_anchor=None)
    return axes


def map(result: Mapping[str, Any], column: str = "lambda_4_plus", ax: AxesArg = None, curves: bool = True,
        **options: Any) -> "Axes":
    """A panel of ``vrw map``'s ``map.png`` from a ``MapResult``: ``column`` of ``map.csv`` over the two
    parameters with a colour bar (the DLS indicators on the command line's diverging scale, white at zero,
    other numbers on viridis; ``"branch"``: the impact branch, unstable gaits dotted, as panel (d)), grey
    where there is no gait; with ``curves`` the threshold curves over it in the command line's colours, with a
    white halo. An unknown column is a ``ValueError``. Returns the Axes."""
    table, spec = result["map"], result["spec"]
    px, py = spec["x"]["param"], spec["y"]["param"]
    valid = [c for c, v in table.items()
             if c not in (px, py) and (np.asarray(v).dtype.kind in "biuf" or c == "branch")]
    if column not in valid:
        raise ValueError(f"unknown map column {column!r}: one of {', '.join(valid)}")
    axis = _axes(ax, 1, (8, 6))[0]
    from matplotlib import patheffects
    from matplotlib.colors import LinearSegmentedColormap, Normalize, TwoSlopeNorm
    from matplotlib.patches import Patch

    nx = spec["x"]["points"]
    xs, ys = np.asarray(table[px], dtype=float)[:nx], np.asarray(table[py], dtype=float)[::nx]
    grid = np.asarray(table[column]).reshape(len(ys), nx)
    if column == "branch":
        kinds = [(b, f"gait, branch {b}", c) for b, c in _BRANCHES.items() if (grid == b).any()]
        handles = _categories(axis, xs, ys, grid, kinds + [("", "no gait", NO_GAIT)], **options)
        unstable = (grid != "") & (np.asarray(table["stability"]).reshape(grid.shape) != "stable")
        gx, gy = np.meshgrid(xs, ys)
        handles += axis.plot(gx[unstable], gy[unstable], "k.", ms=4, label="dot: unstable or uncertain")
    else:
        values = np.ma.masked_invalid(grid.astype(float))
        lo, hi = (float(values.min()), float(values.max())) if values.count() else (-1.0, 1.0)
        scale: Dict[str, Any] = {"cmap": "viridis"}
        if column.startswith("lambda_"):  # white at zero, each side to its own extreme (map_plot.rs)
            ends = ["#2166AC", "#F7F7F7", "#B2182B"]
            norm = TwoSlopeNorm(0.0, lo, hi) if lo < 0 < hi else Normalize(min(lo, 0.0), max(hi, 0.0))
            ends = ends if lo < 0 < hi else ends[1:] if hi > 0 else ends[:2]
            scale = {"norm": norm, "cmap": LinearSegmentedColormap.from_list("vrw_diverging", ends)}
        mesh = axis.pcolormesh(xs, ys, values, shading="nearest", **{**scale, **options})
        mesh.set_cmap(mesh.get_cmap().with_extremes(bad=NO_GAIT))
        axis.figure.colorbar(mesh, ax=axis, label=_label(column))
        handles = [Patch(facecolor=NO_GAIT, edgecolor=FRAME, label="no gait")]
    halo = [patheffects.Stroke(linewidth=4.5, foreground="white"), patheffects.Normal()]
    for curve in sorted(result.get("curves", []) if curves else [], key=lambda c: c["name"]):
        text, color, dashed = _THRESHOLDS.get(curve["name"], _UNCONFIRMED)
        points = np.asarray(curve["points"], dtype=float).reshape(-1, 2)
        if curve.get("closed") and len(points) > 1:
            points = np.vstack([points, points[:1]])
        new = text not in [h.get_label() for h in handles]
        line = axis.plot(points[:, 0], points[:, 1], color=color, ls="--" if dashed else "-", lw=2,
                         marker="o" if len(points) == 1 else None, mec="white", path_effects=halo,
                         label=text if new else "_nolegend_")[0]
        handles += [line] if new else []
    _legend(axis, handles, ncol=3, **_ABOVE)
    axis.set_xlabel(_label(px))
    axis.set_ylabel(_label(py))
    return axis


def orbit(result: Mapping[str, Any], ax: AxesArg = None, branch: bool = True,
          columns: Optional[Sequence[str]] = None, **options: Any) -> Any:
    """The orbit diagram of ``vrw orbit`` (``orbit.png``) from an ``OrbitResult``: for each of ``columns`` of
    ``orbit.csv`` (the command line's: dtheta/dt on the section and lambda_I4), the recorded steps against the
    parameter as small blue dots, grey where the walk fails, and with ``branch`` the period-1 branch (black
    solid where stable, vermillion dashed where unstable, grey dashed where uncertain). ``ax``: an Axes per
    column. An unknown column is a ``ValueError``. Returns the Axes (one column) or their array. Another
    walker's diagram (``vrw.Params(model=...)``) draws by default its section's first coordinate and
    lambda_I4, as ``vrw orbit --model`` does."""
    table = result["orbit"]
    span = result["spec"]["range"] if "spec" in result else result["range"]  # the wheel's, a walker's
    if columns is None:
        walker = "spec" not in result
        columns = (list(table)[4], "lambda_I4") if walker else ("thetadot", "lambda_I4")
    key, lo, hi = span["param"], min(span["from"], span["to"]), max(span["from"], span["to"])
    valid = [c for c, v in table.items() if c != key and np.asarray(v).dtype.kind == "f"]
    if any(c not in valid for c in columns):
        raise ValueError(f"unknown orbit column in {list(columns)}: each one of {', '.join(valid)}")
    axes = _axes(ax, len(columns), (11, 1.2 + 3.2 * len(columns)))
    x, status = np.asarray(table[key], dtype=float), np.asarray(table["status"])
    half = 0.5 * (hi - lo) / (max(span["points"], 2) - 1)  # a failed value shades half a spacing around it
    failed = {f"walk fails: {s.replace('_', ' ')}": [(v - half, v + half) for v in x[status == s]]
              for s in np.unique(status[status != "walking"])}
    styles = {"stable": ("period-1 gait, stable", BLACK, "-"),
              "unstable": ("period-1 gait, unstable", VERMILLION, "--")}
    gaits = result.get("branch") if branch else None
    for axis, column in zip(axes, columns):
        for label, spans in failed.items():
            _spans(axis, spans, FAILED, label)
        axis.plot(x, table[column], **{"ls": "", "marker": "o", "ms": 2.5, "color": BLUE,
                                       "label": "walk after the transient", **options})
        # The branch in stretches of one stability, each from the last point of the one before (no gap).
        stretches: List[Tuple[str, List[float], List[float]]] = []
        for p, v, kind in zip(*(gaits[c] for c in (key, column, "stability"))) if gaits and column in gaits \
                else ():
            if not math.isfinite(v):
                stretches.append(("", [], []))
            elif stretches and stretches[-1][0] == kind:
                stretches[-1][1].append(p)
                stretches[-1][2].append(v)
            else:
                before = stretches[-1] if stretches else ("", [], [])
                stretches.append((kind, before[1][-1:] + [p], before[2][-1:] + [v]))
        for kind, bx, by in (s for s in stretches if s[1]):
            label, color, ls = styles.get(kind, ("period-1 gait, uncertain", MARK, "--"))
            drawn = label in axis.get_legend_handles_labels()[1]
            axis.plot(bx, by, color=color, linestyle=ls, lw=2, label="_nolegend_" if drawn else label)
        axis.set_ylabel(_label(column))
    _legend(axes[0])
    axes[-1].set_xlim(lo, hi)
    axes[-1].set_xlabel(_label(key))
    return axes[0] if len(axes) == 1 else axes


def basin(result: Mapping[str, Any], ax: AxesArg = None, **options: Any) -> "Axes":
    """The basin of ``vrw basin`` (``basin.png``) from a ``BasinResult``: every start of the grid on the slice
    coloured by its outcome (reaches the gait, settles on another, fails and how; a legend of the outcomes
    present), the gait's section states marked with a circled cross. Returns the Axes."""
    spec, points = result["spec"], result["points"]
    cx, cy = spec["x"]["coordinate"], spec["y"]["coordinate"]
    axis = _axes(ax, 1, (9, 6.5))[0]
    ix, iy = np.asarray(points["ix"]), np.asarray(points["iy"])
    xs, ys = np.full(spec["x"]["points"], np.nan), np.full(spec["y"]["points"], np.nan)
    xs[ix], ys[iy] = points[cx], points[cy]
    grid = np.full((len(ys), len(xs)), "undecided", dtype=object)
    grid[iy, ix] = points["outcome"]
    kinds = [(k, _OUTCOME_TEXT.get(k, f"fails: {k.replace('_', ' ')}"), _OUTCOMES.get(k, MARK))
             for k in sorted(set(grid.flat), key=lambda k: (_OUTCOME_ORDER.get(k, 2), k))]
    handles: List[Any] = _categories(axis, xs, ys, grid, kinds, **options)
    labels = [text for _, text, _ in kinds]
    cycle = (result.get("gait") or {}).get("cycle", [])
    if cycle:
        gx, gy = [s["section"][cx] for s in cycle], [s["section"][cy] for s in cycle]
        ring = axis.plot(gx, gy, ls="", marker="o", ms=13, mfc="white", mec="black", mew=2)[0]
        cross = axis.plot(gx, gy, ls="", marker="x", ms=7, color="black", mew=2)[0]
        handles.append((ring, cross))
        labels.append("the gait" if len(cycle) == 1 else f"the gait ({len(cycle)} states)")
    _legend(axis, handles, labels)
    third = next(c for c in ("L2", "thetadot", "L2dot") if c not in (cx, cy))
    axis.set_title(f"slice {third} = {spec['through'][third]:.4f}")
    axis.set_xlabel(_label(cx))
    axis.set_ylabel(_label(cy))
    return axis
