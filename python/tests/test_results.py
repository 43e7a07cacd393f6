"""Result objects: attribute access and dict access alike, readable reprs, tables as DataFrames with the CSV's
column names and dtypes, grids as xarray Datasets over the two parameters, and pickling."""

import pickle

import numpy as np
import pytest

import vrw
from vrw.grid import gait_grid
from conftest import ROOT, assert_table_equals_csv

pd = pytest.importorskip("pandas")
xr = pytest.importorskip("xarray")


def test_run_tables_convert_to_dataframes_like_the_csv_files(cli, tmp_path):
    cli("simulate", "--steps", 3, "--out", tmp_path)
    run = vrw.simulate(vrw.Params(), steps=3)
    assert isinstance(run, dict) and run.status == run["status"] == "completed"
    assert "Run(status='completed', 3 steps" in repr(run)
    for name in ["steps", "trajectory"]:
        frame = getattr(run, name).to_pandas()
        csv = pd.read_csv(tmp_path / f"{name}.csv")
        assert list(frame.columns) == list(csv.columns), name
        assert frame.shape == csv.shape, name
        for column in csv.columns:
            if csv[column].dtype.kind in "fi":
                # Numbers: the CSV's own dtype (float64, or int64 for counts), equal values.
                assert frame[column].dtype.kind in "fi", column
                assert np.allclose(frame[column], csv[column], rtol=1e-12, atol=0, equal_nan=True), column
        # Words: the dtype pandas itself reads them with.
        for column in frame.columns:
            if frame[column].dtype.kind not in "fib":
                assert frame[column].dtype == csv[column].dtype, column


def test_a_run_with_friction_has_the_friction_columns_of_its_steps_csv(cli, tmp_path):
    cli("simulate", "--steps", 2, "--set", "friction=0.6", "--out", tmp_path)
    run = vrw.simulate(vrw.Params(friction=0.6), steps=2)
    frame = run.steps.to_pandas()
    csv = pd.read_csv(tmp_path / "steps.csv")
    assert list(frame.columns) == list(csv.columns)
    assert list(csv.columns[-4:]) == ["friction_loss", "cone_violation", "cone_violation_impulse", "slip_power"]
    assert np.allclose(frame["friction_loss"], csv["friction_loss"], rtol=1e-12, atol=0)
    assert (frame["friction_loss"] > 0.1).all() and (frame["slip_power"] == 0).all()
    assert "friction_loss" not in vrw.simulate(vrw.Params(), steps=1).steps.to_pandas().columns


def test_the_stroke_limited_run_says_which_stop_holds_a_leg(cli, tmp_path):
    # lock1 / lock2: 1 on the stopper, 2 on the compression stop (min_length), as trajectory.csv has them.
    params = vrw.Params.from_toml(ROOT / "readings" / "stroke-limited.toml")
    cli("simulate", "--steps", 2, "--config", ROOT / "readings" / "stroke-limited.toml", "--out", tmp_path)
    run = vrw.simulate(params, steps=2)
    frame = run.trajectory.to_pandas()
    csv = pd.read_csv(tmp_path / "trajectory.csv")
    for column in ["lock1", "lock2", "L1", "L2"]:
        assert np.array_equal(frame[column], csv[column]), column
    assert 2 in set(frame["lock1"]) <= {0, 1, 2} and frame["lock1"].dtype.kind == "i"
    held = frame[frame["lock1"] == 2]
    assert np.allclose(held["L1"], 1.0, atol=1e-9, rtol=0)
    assert frame["L1"].min() > 1.0 - 1e-9 and frame["L2"].min() > 1.0 - 1e-9


def test_gait_and_sweep_results_read_as_attributes():
    gait = vrw.find_gait(vrw.Params())
    assert gait.lambda_4_plus == gait["lambda_4_plus"]
    assert repr(gait).startswith("GaitResult(found, period 1, branch DLS")
    with pytest.raises(AttributeError, match="no field"):
        gait.no_such_field
    result = vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(40, 60, 5))
    frame = result.to_pandas()
    assert frame.shape == (5, len(result.sweep))
    assert frame["viscosity"].dtype == np.float64
    assert frame["stability"].dtype == pd.Series(["stable"]).dtype  # pandas' own dtype for words
    assert frame["scuffing"].dtype == bool and frame["period_k"].dtype == np.int64
    assert "SweepResult(viscosity: 5 points" in repr(result)
    for r in [gait, result]:
        again = pickle.loads(pickle.dumps(r))
        assert type(again) is type(r) and again.keys() == r.keys()


def test_grid_converts_to_an_xarray_dataset_over_both_parameters():
    x = ("viscosity", [40.0, 50.0, 60.0])
    y = ("stiffness", [480.0, 520.0])
    grid = gait_grid(None, vrw.Params(), x=x, y=y)
    ds = grid.to_xarray()
    assert dict(ds.sizes) == {"stiffness": 2, "viscosity": 3}
    assert list(ds["viscosity"].values) == x[1] and list(ds["stiffness"].values) == y[1]
    assert ds["lambda_4_plus"].dims == ("stiffness", "viscosity")
    assert ds["lambda_4_plus"].dtype == np.float64
    np.testing.assert_array_equal(ds["lambda_4_plus"].values, grid.sweep["lambda_4_plus"])
    assert ds.attrs["gaits_found"] == grid.gaits_found
    assert "Grid(stiffness (2) x viscosity (3)" in repr(grid)


def test_basin_equals_basin_csv_and_converts_to_a_grid(cli, tmp_path):
    cli("basin", "--nx", 5, "--ny", 4, "--out", tmp_path)
    result = vrw.basin(vrw.Params(), nx=5, ny=4)
    csv = pd.read_csv(tmp_path / "basin.csv")
    frame = result.to_pandas()
    assert list(frame.columns) == list(csv.columns) and frame.shape == (20, len(csv.columns))
    assert list(frame["outcome"]) == list(csv["outcome"])
    assert np.allclose(frame["thetadot"], csv["thetadot"], rtol=1e-15, atol=0)
    expected = __import__("json").loads((tmp_path / "basin.json").read_text())
    assert result.outcomes == expected["outcomes"]
    ds = result.to_xarray()
    assert dict(ds.sizes) == {"thetadot": 4, "L2": 5}
    assert ds["outcome"].dims == ("thetadot", "L2")
    assert repr(result).startswith("BasinResult(20 starts")
    with pytest.raises(vrw.ConfigError, match="`x`"):
        vrw.basin(vrw.Params(), x="theta", nx=3, ny=3)


def test_continue_family_equals_branch_csv(cli, tmp_path):
    args = ["--param", "slope", "--from", "0.3", "--to", "0.34", "--start", "0.32", "--no-switch"]
    cli("continue", *args, "--out", tmp_path)
    result = vrw.continue_family(vrw.Params(), "slope", start=0.32, range=(0.3, 0.34), switch=False)
    csv = pd.read_csv(tmp_path / "branch.csv")
    frame = result.to_pandas()
    assert list(frame.columns) == list(csv.columns) and frame.shape == csv.shape
    assert list(frame["signature"]) == list(csv["signature"])
    assert list(frame["stability"]) == list(csv["stability"])
    for column in ["slope", "thetadot", "mu1_re", "arclength"]:
        assert np.array_equal(frame[column].to_numpy(), csv[column].to_numpy()), column
    expected = __import__("json").loads((tmp_path / "special_points.json").read_text())
    assert [p["kind"] for p in result.special_points] == ["LP"]
    assert result.special_points[0]["param"] == expected["special_points"][0]["param"]
    assert list(result.families[0]["ends"]) == expected["families"][0]["ends"]
    assert repr(result).startswith("FamilyResult(slope: 1 families,")
    with pytest.raises(ValueError, match="outside the range"):
        vrw.continue_family(vrw.Params(), "slope", start=0.5, range=(0.3, 0.34))
    with pytest.raises(vrw.ConfigError, match="max_points"):
        vrw.continue_family(vrw.Params(), max_points=-1)


def test_continue_family_extremum_equals_the_command_line(cli, tmp_path):
    args = ["--param", "slope", "--from", "0.2", "--to", "0.3", "--start", "0.25", "--no-switch"]
    cli("continue", *args, "--extremum", "lambda_2_plus", "--extremum", "speed", "--out", tmp_path)
    result = vrw.continue_family(
        vrw.Params(), "slope", start=0.25, range=(0.2, 0.3), switch=False, extremum=["lambda_2_plus", "speed"]
    )
    expected = __import__("json").loads((tmp_path / "special_points.json").read_text())
    found = [p for p in result.special_points if p["kind"] == "EX"]
    assert len(found) == 1 and found[0]["extremum"]["quantity"] == "lambda_2_plus"
    assert found[0]["extremum"]["extremum"] == "max" and found[0]["extremum"]["shape"] == "smooth"
    written = [p for p in expected["special_points"] if p["kind"] == "EX"]
    assert [p["param"] for p in found] == [p["param"] for p in written]
    assert [list(p["extremum"]["located_bracket"]) for p in found] == [
        p["extremum"]["located_bracket"] for p in written
    ]
    assert [p["extremum"]["value"] for p in found] == [p["extremum"]["value"] for p in written]
    assert_table_equals_csv(result["monitored"], tmp_path / "monitored.csv")
    assert "monitored" not in vrw.continue_family(vrw.Params(), "slope", start=0.25, range=(0.2, 0.3), switch=False)
    with pytest.raises(ValueError, match="unknown quantity .* max_floquet"):
        vrw.continue_family(vrw.Params(), extremum=["fastness"])


def test_continue_family_curves_equal_curves_csv(cli, tmp_path):
    args = ["--param", "stiffness", "--set", "viscosity=20", "--from", "585", "--to", "600", "--start", "590"]
    cli("continue", *args, "--no-switch", "--two-param", "viscosity", "--two-range", "18,22", "--out", tmp_path)
    result = vrw.continue_family(
        vrw.Params(viscosity=20),
        "stiffness",
        start=590,
        range=(585, 600),
        switch=False,
        two_param=("viscosity", 18, 22),
    )
    csv = pd.read_csv(tmp_path / "curves.csv")
    frame = result["curve_points"].to_pandas()
    assert list(frame.columns) == list(csv.columns) and frame.shape == csv.shape
    for column in ["stiffness", "viscosity", "thetadot", "test_value"]:
        assert np.array_equal(frame[column].to_numpy(), csv[column].to_numpy()), column
    expected = __import__("json").loads((tmp_path / "special_points.json").read_text())
    assert [dict(c, ends=list(c["ends"])) for c in result["curves"]] == expected["curves"]
    with pytest.raises(ValueError, match="two_param"):
        vrw.continue_family(vrw.Params(), two_param=("viscosity", 1, 10))


def test_map_equals_map_csv_and_curves_json(cli, tmp_path):
    args = ["--x-from", "30", "--x-to", "70", "--nx", "3", "--y-from", "440", "--y-to", "560", "--ny", "3"]
    cli("map", *args, "--out", tmp_path)
    result = vrw.map(vrw.Params(), x_range=(30, 70), nx=3, y_range=(440, 560), ny=3)
    csv = pd.read_csv(tmp_path / "map.csv")
    frame = result.to_pandas()
    assert list(frame.columns) == list(csv.columns) and frame.shape == csv.shape
    for column in csv.columns:
        if csv[column].dtype.kind == "f":
            assert np.array_equal(frame[column], csv[column], equal_nan=True), column
    assert list(frame["status"]) == list(csv["status"])
    expected = __import__("json").loads((tmp_path / "curves.json").read_text())
    assert result.points == expected["points"] == 9 and result.gaits_found == expected["gaits_found"]
    assert [c["name"] for c in result.curves] == [c["name"] for c in expected["curves"]]
    assert [[list(p) for p in c["points"]] for c in result.curves] == [c["points"] for c in expected["curves"]]
    assert [t["threshold"]["value"] for t in result.thresholds] == [
        t["threshold"]["value"] for t in expected["thresholds"]
    ]
    ds = result.to_xarray()
    assert dict(ds.sizes) == {"stiffness": 3, "viscosity": 3}
    assert list(ds["viscosity"].values) == [30.0, 50.0, 70.0]
    assert ds["status"].dims == ("stiffness", "viscosity")
    assert repr(result).startswith("MapResult(viscosity x stiffness: gait at")
    with pytest.raises(vrw.ConfigError, match="curve_method"):
        vrw.map(vrw.Params(), nx=3, ny=3, curve_method="squares")
    with pytest.raises(vrw.ConfigError, match="second_route"):
        vrw.map(vrw.Params(), nx=3, ny=3, curves=False, second_route=True)


def test_orbit_equals_orbit_csv_and_branch_csv(cli, tmp_path):
    args = ["--from", "40", "--to", "60", "--points", "5", "--transient", "4", "--steps", "8"]
    cli("orbit", *args, "--out", tmp_path)
    result = vrw.orbit(vrw.Params(), range=(40, 60), points=5, transient=4, steps=8)
    for name in ["orbit", "branch"]:
        csv = pd.read_csv(tmp_path / f"{name}.csv")
        frame = result[name].to_pandas()
        assert list(frame.columns) == list(csv.columns) and frame.shape == csv.shape, name
        for column in csv.columns:
            if csv[column].dtype.kind == "f":
                assert np.array_equal(frame[column], csv[column], equal_nan=True), (name, column)
    expected = __import__("json").loads((tmp_path / "orbit.json").read_text())
    assert dict(result.outcomes) == expected["outcomes"]
    assert list(result.branch_gaits) == expected["branch_gaits"]
    assert repr(result).startswith("OrbitResult(viscosity: 5 values, outcomes")
    assert "branch" not in vrw.orbit(vrw.Params(), range=(40, 60), points=2, steps=2, branch=False)
    with pytest.raises(vrw.ConfigError, match="steps"):
        vrw.orbit(vrw.Params(), steps=-1)
