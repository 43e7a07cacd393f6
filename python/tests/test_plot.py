"""vrw.plot: the command line's figures on matplotlib axes. Each function draws on the axes given (or a new
figure's), returns them, and they hold the result's data with labelled axes; bad columns and a wrong number
of axes are ValueErrors, and matplotlib is imported only when a figure is drawn."""

import subprocess
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection, QuadMesh  # noqa: E402

import vrw  # noqa: E402
import vrw.plot as vp  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def sweep():
    """Up to and past the loss of the gait near c = 135: a threshold and points without a gait."""
    return vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(100, 160, 7))


@pytest.fixture(scope="module")
def walk():
    return vrw.simulate(vrw.Params(), steps=3)


@pytest.fixture(scope="module")
def gait_map():
    """Two impact branches, an unstable gait and several kinds of threshold curve."""
    return vrw.map(vrw.Params(), x_range=(1, 120), y_range=(500, 900), nx=4, ny=4)


@pytest.fixture(scope="module")
def orbit_result():
    """Walks that fail above c = 135 (shaded) and a period-1 branch."""
    return vrw.orbit(vrw.Params(), range=(100, 160), points=8, transient=8, steps=8)


@pytest.fixture(scope="module")
def basin_result():
    return vrw.basin(vrw.Params(), nx=5, ny=5, max_steps=20)


def rendered(axes):
    """Draw the figure of ``axes`` (mathtext and legends fail only then) and return the axes."""
    first = axes if hasattr(axes, "figure") else np.ravel(axes)[0]
    first.figure.canvas.draw()
    return axes


def line(ax, label):
    """The line of ``ax`` labelled ``label``."""
    found = [l for l in ax.get_lines() if l.get_label() == label]
    assert found, (label, [l.get_label() for l in ax.get_lines()])
    return found[0]


def legend_texts(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_fig2_draws_both_panels_thresholds_and_no_gait(sweep):
    axes = rendered(vp.fig2(sweep))
    assert len(axes) == 2 and axes[0].figure is axes[1].figure
    s, c = sweep.sweep, sweep.sweep["viscosity"]
    panels = {"lambda_I4": (0, "$\\lambda_{I4}$"), "lambda_2_plus": (1, "$\\lambda_2^+$"),
              "lambda_4_plus": (1, "$\\lambda_4^+$")}
    for column, (k, name) in panels.items():
        drawn = line(axes[k], name)
        assert np.array_equal(drawn.get_xdata(), c)
        assert np.array_equal(drawn.get_ydata(), s[column], equal_nan=True)
    assert axes[0].get_ylabel() == "$\\lambda_{I4}$ [N s]" and axes[1].get_ylabel() == "$\\lambda$ [N]"
    assert axes[1].get_xlabel() == "c [N s/m]" and axes[1].get_xlim() == (100, 160)
    # The threshold: a dashed line through both panels, labelled over the top one.
    (value,) = [t["value"] for t in sweep.thresholds]
    for ax in axes:
        (marks,) = [col for col in ax.collections if isinstance(col, LineCollection)]
        assert marks.get_segments()[0][0][0] == pytest.approx(value)
        assert "no gait" in legend_texts(ax) and "scuffing of Leg 2" in legend_texts(ax)
    assert [t.get_text() for t in axes[0].texts] == [f"gait lost: c = {value:.2f}"]


def test_fig2_draws_on_the_axes_given(sweep):
    _, given = plt.subplots(4, 1)
    axes = rendered(vp.fig2(sweep, ax=given, panels=4, ms=3))
    assert all(a is b for a, b in zip(axes, given)) and len(axes) == 4
    assert axes[2].get_ylabel() == "T [s]" and axes[3].get_ylabel() == "max |μ|"
    assert line(axes[3], "largest |multiplier|").get_markersize() == 3
    with pytest.raises(ValueError, match="4 panel"):
        vp.fig2(sweep, ax=given[:2], panels=4)
    with pytest.raises(ValueError, match="panels"):
        vp.fig2(sweep, panels=3)


def test_run_draws_five_panels_against_time(walk):
    axes = rendered(vp.run(walk))
    assert len(axes) == 5
    t = walk.trajectory["time"]
    theta = line(axes[0], "θ")
    x = np.asarray(theta.get_xdata())
    # Every sample, with a break (NaN) at each re-indexing of the legs.
    assert np.array_equal(x[np.isfinite(x)], t)
    assert np.isnan(x).sum() == np.count_nonzero(np.diff(walk.trajectory["leg1"]))
    assert [a.get_ylabel() for a in axes] == [
        "θ of Leg 1 [rad]", "dθ/dt [rad/s]", "leg length [m]", "normal force [N]", "tangential force [N]"]
    assert axes[-1].get_xlabel() == "time t [s]"
    assert "$L_0$ = 1 m" in legend_texts(axes[2])
    # Phases shaded in every panel, touchdowns dashed; the phases' legend over the top panel.
    for ax in axes:
        assert any(isinstance(c, PolyCollection) for c in ax.collections)
        assert any(isinstance(c, LineCollection) for c in ax.collections)
    assert "DLS" in legend_texts(axes[0]) and "touchdown" in legend_texts(axes[0])
    _, given = plt.subplots(5, 1)
    assert all(a is b for a, b in zip(vp.run(walk, ax=given), given))


def test_run_draws_the_compression_stop_where_there_is_one():
    stroke = vrw.Params(rear_exit="reset", rear_stopper=False, min_length=1.0, stopper_length=1.02,
                        spring_natural_length=1.02)
    axes = rendered(vp.run(vrw.simulate(stroke, steps=2)))
    assert {"$L_0$ = 1.02 m", "min_length = 1 m"} <= set(legend_texts(axes[2]))
    assert "min_length" not in " ".join(legend_texts(rendered(vp.run(vrw.simulate(vrw.Params(), steps=1)))[2]))


def test_run_needs_the_trajectory():
    with pytest.raises(ValueError, match="trajectory"):
        vp.run(vrw.simulate(vrw.Params(), steps=1, trajectory=False))


def test_steps_draws_indicators_per_step_and_the_portrait(walk):
    axes = rendered(vp.steps(walk))
    assert len(axes) == 6
    drawn = line(axes[0], "$\\lambda_{I4}$")
    assert np.array_equal(drawn.get_xdata(), walk.steps["step"])
    assert np.array_equal(drawn.get_ydata(), walk.steps["lambda_I4"])
    assert axes[4].get_xlabel() == "step number" and axes[3].get_ylabel() == "energy [J]"
    assert legend_texts(axes[3]) == ["loss of T + V", "damper", "impacts", "stoppers"]
    portrait = axes[5]
    assert any(isinstance(c, LineCollection) for c in portrait.collections)
    assert portrait.get_xlabel() == "$L_2$ [m]" and "step 3" in portrait.get_title()
    _, given = plt.subplots(6, 1)
    assert all(a is b for a, b in zip(vp.steps(walk, ax=given), given))


def test_map_draws_the_column_and_the_curves(gait_map):
    fig, given = plt.subplots()
    ax = rendered(vp.map(gait_map, "lambda_4_plus", ax=given))
    assert ax is given
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    values = np.ma.filled(mesh.get_array().astype(float), np.nan).reshape(4, 4)
    expected = np.asarray(gait_map.map["lambda_4_plus"]).reshape(4, 4)
    assert np.array_equal(values, expected, equal_nan=True)
    assert np.isnan(expected).any()  # shown grey: the colour map's "bad" colour
    assert mesh.get_cmap().get_bad()[:3] == pytest.approx((200 / 255,) * 3)
    assert len(fig.axes) == 2 and fig.axes[1].get_ylabel() == "$\\lambda_4^+$ [N]"  # the colour bar
    assert ax.get_xlabel() == "c [N s/m]" and ax.get_ylabel() == "k [N/m]"
    curves = gait_map.curves
    assert len(ax.get_lines()) == len(curves)
    assert {"end of the gait", "$\\lambda_2^+ = 0$", "no gait"} <= set(legend_texts(ax))
    first = sorted(curves, key=lambda c: c["name"])[0]
    assert np.allclose(ax.get_lines()[0].get_xdata(), [p[0] for p in first["points"]])


def test_map_branch_column_and_without_curves(gait_map):
    ax = rendered(vp.map(gait_map, "branch", curves=False))
    texts = legend_texts(ax)
    assert {"gait, branch DLS", "gait, branch BOUNCE", "no gait", "dot: unstable or uncertain"} <= set(texts)
    (dots,) = ax.get_lines()  # the unstable gaits only: no curve
    assert len(dots.get_xdata()) == np.count_nonzero(gait_map.map["stability"] == "unstable")


def test_map_refuses_an_unknown_column(gait_map):
    with pytest.raises(ValueError, match="'lambda_5'.*branch.*lambda_2_plus"):
        vp.map(gait_map, "lambda_5")
    with pytest.raises(ValueError, match="'message'"):
        vp.map(gait_map, "message")


def test_orbit_draws_dots_branch_and_failures(orbit_result):
    axes = rendered(vp.orbit(orbit_result))
    assert len(axes) == 2
    o = orbit_result.orbit
    dots = line(axes[0], "walk after the transient")
    assert np.array_equal(dots.get_xdata(), o["viscosity"])
    assert np.array_equal(dots.get_ydata(), o["thetadot"], equal_nan=True)
    assert line(axes[1], "period-1 gait, stable").get_linestyle() == "-"
    assert axes[0].get_ylabel() == "dθ/dt [rad/s]" and axes[1].get_ylabel() == "$\\lambda_{I4}$ [N s]"
    assert axes[1].get_xlabel() == "c [N s/m]" and axes[1].get_xlim() == (100, 160)
    assert "walk fails: rolled back" in legend_texts(axes[0])
    fig, given = plt.subplots()
    one = vp.orbit(orbit_result, ax=given, columns=["lambda_4_plus"], branch=False)
    assert one is given and [l.get_label() for l in one.get_lines()] == ["walk after the transient"]
    with pytest.raises(ValueError, match="'speed'"):
        vp.orbit(orbit_result, columns=["speed"])


def test_basin_colours_the_outcomes_and_marks_the_gait(basin_result):
    fig, given = plt.subplots()
    ax = rendered(vp.basin(basin_result, ax=given))
    assert ax is given
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    assert mesh.get_array().size == 25
    texts = legend_texts(ax)
    assert texts[0] == "reaches the gait" and texts[-1] == "the gait"
    assert "not a section state" in texts
    section = basin_result.gait["section"]
    ring = ax.get_lines()[0]
    assert ring.get_xdata()[0] == section["L2"] and ring.get_ydata()[0] == section["thetadot"]
    assert ax.get_xlabel() == "L2 [m]" and ax.get_ylabel() == "dθ/dt [rad/s]"
    assert ax.get_title().startswith("slice L2dot = ")


def test_save_one_figure_of_each(sweep, walk, gait_map, orbit_result, basin_result, tmp_path):
    for name, axes in [("fig2", vp.fig2(sweep)), ("run", vp.run(walk)), ("steps", vp.steps(walk)),
                       ("map", vp.map(gait_map)), ("orbit", vp.orbit(orbit_result)),
                       ("basin", vp.basin(basin_result))]:
        first = axes if hasattr(axes, "figure") else axes[0]
        first.figure.savefig(tmp_path / f"{name}.png", dpi=50)
        assert (tmp_path / f"{name}.png").stat().st_size > 1000


def test_matplotlib_is_imported_only_to_draw(monkeypatch, basin_result):
    code = "import sys, vrw.plot; print('matplotlib' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)  # as if it were not installed
    with pytest.raises(ImportError, match="pip install matplotlib"):
        vp.basin(basin_result)
