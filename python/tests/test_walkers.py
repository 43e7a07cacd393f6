"""The walkers other than the wheel from Python (``vrw.Params(model=...)``): their parameters validated by the
library, every job the command line runs for them with its numbers (compared with the files of the same
``vrw ... --model`` command, value for value), pickling, the errors of bad input, and the wheel's API
unchanged."""

import doctest
import json
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest

import vrw
from conftest import ROOT, assert_table_equals_csv, json_equal, read_csv

COMPASS_TOML = str(ROOT / "models" / "compass.toml")
THREE_DEGREES = 0.0523598775598
# The paper's gaits, as the README quotes `vrw gait --model ...` (9 digits).
SIMPLEST_GAIT = {"theta": 0.200310901, "theta_dot": -0.199832473, "period": 3.882463753}
COMPASS_GAIT = {"theta1": 0.271028680, "period": 0.734346391}


def read_json(path):
    return json.loads(Path(path).read_text())


def gait_json(cli, tmp_path, *args):
    """`vrw gait ARGS`'s gait.json."""
    cli("gait", *args, "--out", tmp_path / "gait")
    return read_json(tmp_path / "gait" / "gait.json")


# --- Params ---------------------------------------------------------------------------------------------


def test_a_walkers_params_hold_its_keys_validated_and_say_its_model():
    p = vrw.Params(model="compass", slope=0.05, hip_mass=10)
    assert p.model == "compass"
    assert p.parameter_keys() == ["hip_mass", "leg_mass", "leg_length", "leg_mass_offset", "gravity", "slope"]
    assert p.parameter_keys() == list(p.to_dict())
    assert p["slope"] == 0.05 and p["hip_mass"] == 10.0
    assert p.to_dict()["leg_mass"] == 5.0
    assert repr(p) == "Params(model='compass', slope=0.05)"
    q = p.replace(leg_mass=4)
    assert q["leg_mass"] == 4.0 and q["slope"] == 0.05 and p["leg_mass"] == 5.0
    assert p == vrw.Params(model="compass", slope=0.05) and p != q
    assert vrw.Params(model="simplest").parameter_keys() == ["slope"]
    with pytest.raises(KeyError):
        p["viscosity"]
    assert vrw.Params(model="simplest") != vrw.Params(model="compass")
    assert vrw.Params(model="simplest") != vrw.Params()


def test_a_walkers_params_read_a_toml_file(tmp_path):
    path = tmp_path / "walker.toml"
    path.write_text("slope = 0.012\n")
    p = vrw.Params.from_toml(path, model="simplest")
    assert p == vrw.Params(model="simplest", slope=0.012)
    with pytest.raises(vrw.ConfigError, match="hip_mass"):
        path.write_text("hip_mass = 3\n")
        vrw.Params.from_toml(path, model="simplest")


def test_a_described_walker_is_the_built_in_compass_gait_to_1e_10():
    described = vrw.Params(model=COMPASS_TOML, slope=THREE_DEGREES)
    assert described.model == COMPASS_TOML
    built_in = vrw.find_gait(vrw.Params(model="compass", slope=THREE_DEGREES))
    gait = vrw.find_gait(described)
    assert gait["model"] == "compass-toml" and gait["status"] == "found"
    assert list(gait["section"]) == list(built_in["section"])
    for name in gait["section"]:
        assert gait["section"][name] == pytest.approx(built_in["section"][name], abs=1e-10)
    assert gait["period"] == pytest.approx(built_in["period"], abs=1e-10)
    assert np.abs(gait["floquet_multipliers"] - built_in["floquet_multipliers"]).max() < 1e-10


@pytest.mark.parametrize(
    "params",
    [
        vrw.Params(model="simplest", slope=0.011),
        vrw.Params(model="compass", slope=0.06, hip_mass=8),
        vrw.Params(model="telescopic", viscosity=900),
        vrw.Params(model=COMPASS_TOML, slope=0.05),
    ],
    ids=["simplest", "compass", "telescopic", "described"],
)
def test_a_walkers_params_pickle(params):
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        again = pickle.loads(pickle.dumps(params, protocol=protocol))
        assert again == params and again.model == params.model and again.to_dict() == params.to_dict()


def test_a_pickled_description_needs_no_file(tmp_path):
    """A described walker's Params carry the description: a process without the file (a Dask worker on
    another machine) reads it back."""
    path = tmp_path / "compass.toml"
    shutil.copy(COMPASS_TOML, path)
    params = vrw.Params(model=str(path), slope=THREE_DEGREES)
    data = pickle.dumps(params)
    path.unlink()
    again = pickle.loads(data)
    assert again == params
    assert vrw.find_gait(again)["period"] == vrw.find_gait(params)["period"]


def same(a, b):
    """The same value, through dicts, lists and numpy arrays (NaN equal to NaN)."""
    if isinstance(a, dict):
        return type(a) is type(b) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, np.ndarray):
        return a.dtype == b.dtype and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc")
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b or (a != a and b != b)


def test_results_of_a_walker_pickle():
    params = vrw.Params(model="simplest")
    for result in (vrw.find_gait(params), vrw.simulate(params, steps=2),
                   vrw.sweep(params, "slope", [0.008, 0.009]),
                   vrw.continue_family(params, "slope", range=(0.008, 0.01)),
                   vrw.orbit(params, "slope", range=(0.01, 0.011), points=2, transient=2, steps=2)):
        again = pickle.loads(pickle.dumps(result))
        assert same(again, result), type(result)


def test_the_wheels_params_are_unchanged():
    assert vrw.Params().model == "vrw"
    assert vrw.Params(model="vrw", viscosity=37) == vrw.Params(viscosity=37)
    assert repr(vrw.Params(viscosity=37)) == "Params(viscosity=37.0)"
    assert vrw.Params().parameter_keys() == vrw.Params.numeric_keys()
    assert "viscosity" in vrw.Params.numeric_keys()
    assert pickle.loads(pickle.dumps(vrw.Params(viscosity=37))) == vrw.Params(viscosity=37)


# --- Bad input ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "keys, message",
    [
        ({"model": "bicycle"}, "unknown model \"bicycle\""),
        ({"model": "simplest", "hip_mass": 10}, "unknown key `hip_mass`"),
        ({"model": "compass", "viscosity": 37}, "unknown key `viscosity`"),  # a wheel key
        ({"model": "compass", "slope": "steep"}, "wrong type for `slope`"),
        ({"model": "compass", "slope": True}, "wrong type for `slope`"),
        ({"model": "compass", "hip_mass": -1}, "hip_mass"),
        ({"model": "no/such/walker.toml"}, "no/such/walker.toml"),
    ],
    ids=["unknown model", "unknown key", "wheel key", "string", "bool", "negative mass", "missing file"],
)
def test_bad_walker_params_raise_config_error_naming_the_problem(keys, message):
    with pytest.raises(vrw.ConfigError, match=message.replace("(", r"\(")):
        vrw.Params(**keys)


def test_a_malformed_description_names_its_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(Path(COMPASS_TOML).read_text().replace('kind = "revolute"', 'kind = "hinge"', 1))
    with pytest.raises(vrw.ConfigError, match=r"bad.toml line \d+: unknown variant `hinge`"):
        vrw.Params(model=str(bad))


@pytest.mark.parametrize(
    "job, words",
    [
        (lambda p: vrw.map(p, x="slope", y="viscosity", nx=2, ny=2), "has no parameter \"viscosity\""),
        (lambda p: vrw.map(p, x="slope", y="slope"), "different parameters"),
        (lambda p: vrw.map(p, x="slope", x_range=(0.01, 0.02), curve_method="crossings"), "`curve_method`"),
        (lambda p: vrw.map(p, x="slope", x_range=(0.01, 0.02), second_route=True), "`second_route`"),
        (lambda p: vrw.map(p, x="slope", x_range=(0.01, 0.02), curves=False, rows=(0, 1)), "`rows`"),
        (lambda p: vrw.basin(p, x="L2"), "\"L2\" is not a coordinate of the section of `simplest`"),
        (lambda p: vrw.basin(p, nx=2, ny=2, rows=(0, 1)), "`rows`"),
        (lambda p: vrw.sweep(p, "hip_mass", [1, 2]), "has no parameter \"hip_mass\""),
        (lambda p: vrw.sweep(p, "slope", [0.01, 2.0]), "between -pi/2 and pi/2"),
        (lambda p: vrw.sweep(p, "slope", [0.01, 0.02], progress=print), "`progress`"),
        (lambda p: vrw.simulate(p, initial=[0.2]), "1 values given; the section of `simplest` has 2"),
        (lambda p: vrw.continue_family(p, "slope", range=(0.005, 0.017), two_param=("slope", 0, 1)),
         "`two_param`"),
        (lambda p: vrw.continue_family(p, "slope", range=(0.005, 0.017), extremum=["speed"]),
         "invalid `extremum`: is an option of the wheel's continuation"),
        (lambda p: vrw.orbit(p, "slope", range=(0.01, 0.011), points=2, part="coarse"), "`part`"),
    ],
    ids=["map key", "map axes", "curve_method", "second_route", "map rows", "basin coordinate", "basin rows",
         "sweep key", "sweep value", "progress", "initial", "two_param", "extremum", "part"],
)
def test_a_job_a_walker_does_not_run_raises_config_error_naming_the_model(job, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(")) as raised:
        job(vrw.Params(model="simplest"))
    assert "simplest" in str(raised.value) or "slope" in str(raised.value)


def test_the_telescopic_walker_walks_from_python_as_on_the_command_line(cli, tmp_path):
    p = vrw.Params(model="telescopic")
    run = vrw.simulate(p, steps=2)
    cli("simulate", "--model", "telescopic", "--steps", "2", "--out", tmp_path / "t")
    assert_table_equals_csv(run.steps, tmp_path / "t" / "steps.csv")
    assert list(run.steps["branch"]) == ["DLS", "DLS"]
    with pytest.raises(TypeError, match="tolerance"):
        vrw.find_gait(vrw.Params(model="simplest"), tolerance=1e-9)


def test_a_described_walker_walks_as_its_built_in(cli, tmp_path):
    run = vrw.simulate(vrw.Params(model=COMPASS_TOML), steps=2)
    assert run["model"] == "compass-toml"
    cli("simulate", "--model", "compass", "--steps", "2", "--out", tmp_path / "c")
    assert_table_equals_csv(run.steps, tmp_path / "c" / "steps.csv")


# --- The jobs, against the command line -----------------------------------------------------------------


@pytest.mark.parametrize(
    "model, slope, paper",
    [("simplest", "0.009", SIMPLEST_GAIT), ("compass", str(THREE_DEGREES), COMPASS_GAIT)],
)
def test_find_gait_is_vrw_gait_model(cli, tmp_path, model, slope, paper):
    gait = vrw.find_gait(vrw.Params(model=model, slope=float(slope)))
    assert isinstance(gait, vrw.GaitResult) and gait["model"] == model and gait["stable"]
    expected = gait_json(cli, tmp_path, "--model", model, "--set", f"slope={slope}")
    flat = {k: v for k, v in expected.items() if k != "gait"} | expected["gait"]
    assert set(gait) == set(flat) | {"stable"}
    for key, value in flat.items():
        assert json_equal(gait[key], value), key
    for key, value in paper.items():
        got = gait["period"] if key == "period" else gait["section"][key]
        assert round(got, 9) == value, key
    assert gait["lambda_I4"] < 0  # the traditional impact (README)
    assert model in repr(gait)


def test_find_gait_takes_the_transient_and_dp_dparam(cli, tmp_path):
    p = vrw.Params(model="compass")
    gait = vrw.find_gait(p, transient_steps=5, parameter="hip_mass", initial=[0.27, -1.09, -0.38])
    expected = gait_json(cli, tmp_path, "--model", "compass", "--transient", "5", "--parameter", "hip_mass",
                         "--initial", "0.27,-1.09,-0.38")
    assert json_equal(gait["dP_dparam"], expected["gait"]["dP_dparam"])
    assert json_equal(gait["section"], expected["gait"]["section"])


def test_find_gait_of_the_telescopic_walker_takes_dp_dparam(cli, tmp_path):
    p = vrw.Params(model="telescopic")
    gait = vrw.find_gait(p, parameter="stopper_length")
    expected = gait_json(cli, tmp_path, "--model", "telescopic", "--parameter", "stopper_length")
    assert gait["dP_dparam"]["derivative"] == "exact_replay"
    assert json_equal(gait["dP_dparam"], expected["gait"]["dP_dparam"])
    with pytest.raises(vrw.ConfigError, match="`stifness` is not a parameter of the model `telescopic`"):
        vrw.find_gait(p, parameter="stifness")


def test_find_gait_of_the_telescopic_walker_is_vrw_gait(cli, tmp_path):
    gait = vrw.find_gait(vrw.Params(model="telescopic"))
    expected = gait_json(cli, tmp_path, "--model", "telescopic")
    flat = {k: v for k, v in expected.items() if k != "gait"} | expected["gait"]
    for key, value in flat.items():
        assert json_equal(gait[key], value), key
    assert gait["stable"] and round(gait["period"], 9) == 0.830835383  # the README's


def test_simulate_is_vrw_simulate_model(cli, tmp_path):
    initial = (0.200310901, -0.199832473)
    run = vrw.simulate(vrw.Params(model="simplest"), steps=10, initial=initial)
    cli("simulate", "--model", "simplest", "--initial", "0.200310901,-0.199832473", "--steps", "10",
        "--out", tmp_path)
    assert isinstance(run, vrw.Run) and isinstance(run.steps, vrw.Table)
    assert_table_equals_csv(run["steps"], tmp_path / "steps.csv")
    assert_table_equals_csv(run["trajectory"], tmp_path / "trajectory.csv")
    summary = read_json(tmp_path / "summary.json")
    for key, value in summary.items():
        if key != "files":
            assert json_equal(run[key], value), key
    assert run.steps.to_pandas().shape == (10, len(run.steps))
    assert run["steps"]["step"].dtype.kind == "i" and run["steps"]["scuffs"].dtype.kind == "i"
    # The README: step 10 starts from theta = 0.200310901 and lasts 3.882463753.
    assert round(run["steps"]["theta"][-1], 9) == 0.200310901 and round(run["steps"]["period"][-1], 9) == 3.882463753
    assert vrw.simulate(vrw.Params(model="simplest"), steps=2, trajectory=False)["trajectory"] is None


@pytest.mark.parametrize(
    "model, range_, threshold",
    [("simplest", ("0.008", "0.017", "19"), 0.015088438), ("compass", ("0.04", "0.08", "21"), 0.076635632)],
)
def test_sweep_is_vrw_sweep_model_at_its_values(cli, tmp_path, model, range_, threshold):
    cli("sweep", "--model", model, "--param", "slope", "--from", range_[0], "--to", range_[1], "--points",
        range_[2], "--out", tmp_path)
    _, rows = read_csv(tmp_path / "sweep.csv")
    values = [float(r[0]) for r in rows]
    result = vrw.sweep(vrw.Params(model=model), "slope", values)
    assert isinstance(result, vrw.SweepResult) and result["model"] == model and result["param"] == "slope"
    assert_table_equals_csv(result["sweep"], tmp_path / "sweep.csv")
    expected = read_json(tmp_path / "thresholds.json")
    for key, value in expected.items():
        if key != "files":
            assert json_equal(result[key], value), key
    assert [round(t["value"], 9) for t in result["thresholds"]] == [threshold]  # the README's
    assert result.to_pandas().shape[0] == len(values)


@pytest.mark.parametrize(
    "model, args, pd",
    [
        ("simplest", dict(range=(0.005, 0.017), start=0.009), 0.015088438),
        ("compass", dict(range=(0.04, 0.08)), 0.076635632),
        (COMPASS_TOML, dict(range=(0.04, 0.08)), 0.076635632),
    ],
    ids=["simplest", "compass", "described"],
)
def test_continue_family_is_vrw_continue_model(cli, tmp_path, model, args, pd):
    family = vrw.continue_family(vrw.Params(model=model), "slope", **args)
    options = ["--from", str(args["range"][0]), "--to", str(args["range"][1])]
    if "start" in args:
        options += ["--start", str(args["start"])]
    cli("continue", "--model", model, "--param", "slope", *options, "--out", tmp_path)
    assert isinstance(family, vrw.FamilyResult)
    assert_table_equals_csv(family["branch"], tmp_path / "branch.csv")
    for key, value in read_json(tmp_path / "special_points.json").items():
        assert json_equal(family[key], value), key
    assert [(p["kind"], round(p["value"], 9)) for p in family["special_points"]] == [("PD", pd)]


def test_orbit_is_vrw_orbit_model(cli, tmp_path):
    p = vrw.Params(model="simplest")
    diagram = vrw.orbit(p, "slope", range=(0.012, 0.0165), points=11, transient=60, steps=16)
    cli("orbit", "--model", "simplest", "--param", "slope", "--from", "0.012", "--to", "0.0165", "--points",
        "11", "--transient", "60", "--steps", "16", "--out", tmp_path)
    assert isinstance(diagram, vrw.OrbitResult)
    assert_table_equals_csv(diagram["orbit"], tmp_path / "orbit.csv")
    assert_table_equals_csv(diagram["branch"], tmp_path / "branch.csv")
    for key, value in read_json(tmp_path / "orbit.json").items():
        if key != "files":
            assert json_equal(diagram[key], value), key
    assert "period_2" in diagram["outcomes"] and "slope" in repr(diagram)
    assert "branch" not in vrw.orbit(p, "slope", range=(0.01, 0.011), points=2, transient=2, steps=2,
                                     branch=False)


def map_args(grid):
    """`vrw map --model ...`'s options for the axes of `grid` (`x`, `x_range`, `nx`, `y`, ...)."""
    args = []
    for a in "xy":
        lo, hi = grid[f"{a}_range"]
        args += [f"--{a}", grid[a], f"--{a}-from", lo, f"--{a}-to", hi, f"--n{a}", grid[f"n{a}"]]
    return args


@pytest.mark.parametrize(
    "model, grid",
    [
        ("compass", dict(x="slope", x_range=(0.07, 0.08), nx=5, y="hip_mass", y_range=(8.0, 12.0), ny=3)),
        ("telescopic", dict(x="viscosity", x_range=(800.0, 1200.0), nx=3, y="stiffness",
                            y_range=(18000.0, 22000.0), ny=2)),
    ],
)
def test_map_is_vrw_map_model(cli, tmp_path, model, grid):
    result = vrw.map(vrw.Params(model=model), **grid)
    cli("map", "--model", model, *map_args(grid), "--out", tmp_path)
    assert isinstance(result, vrw.MapResult) and result["model"] == model
    assert_table_equals_csv(result["map"], tmp_path / "map.csv")
    expected = read_json(tmp_path / "map.json")
    assert set(result) == set(expected) - {"files"} | {"map"}
    for key, value in expected.items():
        if key != "files":
            assert json_equal(result[key], value), key
    # The grid over both parameters, each point the table's row.
    data = result.to_xarray()
    x, y = grid["x"], grid["y"]
    assert data["period"].dims == (y, x) and data["period"].shape == (grid["ny"], grid["nx"])
    table = result["map"].to_pandas()
    row = table.iloc[grid["nx"] + 1]
    assert data["period"].sel({x: row[x], y: row[y]}).item() == row["period"]
    assert model in repr(result)


def test_a_walkers_map_without_thresholds_is_vrw_map_no_curves(cli, tmp_path):
    grid = dict(x="slope", x_range=(0.07, 0.08), nx=4, y="hip_mass", y_range=(8.0, 12.0), ny=2)
    result = vrw.map(vrw.Params(model="compass"), curves=False, initial=[0.29, -1.14, -0.2], **grid)
    cli("map", "--model", "compass", *map_args(grid), "--no-curves", "--initial", "0.29,-1.14,-0.2",
        "--out", tmp_path)
    assert_table_equals_csv(result["map"], tmp_path / "map.csv")
    assert result["thresholds"] == [] == read_json(tmp_path / "map.json")["thresholds"]


@pytest.mark.parametrize(
    "model, options, args",
    [
        ("simplest", dict(x_range=(0.15, 0.25), y_range=(-0.25, -0.15), nx=6, ny=5),
         ["--x-range", "0.15,0.25", "--y-range=-0.25,-0.15", "--nx", "6", "--ny", "5"]),
        ("compass", dict(x="theta1_dot", y="theta2_dot", nx=4, ny=3, max_steps=30, tolerance=1e-4),
         ["--x", "theta1_dot", "--y", "theta2_dot", "--nx", "4", "--ny", "3", "--max-steps", "30",
          "--tolerance", "1e-4"]),
        (COMPASS_TOML, dict(nx=3, ny=3), ["--nx", "3", "--ny", "3"]),
    ],
    ids=["simplest", "compass", "described"],
)
def test_basin_is_vrw_basin_model(cli, tmp_path, model, options, args):
    result = vrw.basin(vrw.Params(model=model), **options)
    cli("basin", "--model", model, *args, "--out", tmp_path)
    assert isinstance(result, vrw.BasinResult)
    assert_table_equals_csv(result["points"], tmp_path / "basin.csv")
    expected = read_json(tmp_path / "basin.json")
    assert set(result) == set(expected) - {"files"} | {"points"}
    for key, value in expected.items():
        if key != "files":
            assert json_equal(result[key], value), key
    assert sum(result["outcomes"].values()) == options["nx"] * options["ny"]
    # The grid over the slice's coordinates, each start the table's row.
    data = result.to_xarray()
    x, y = result["x"]["coordinate"], result["y"]["coordinate"]
    assert data["outcome"].dims == (y, x)
    points = result["points"]
    last = points.rows - 1
    at = {x: points[x][last], y: points[y][last]}
    assert data["outcome"].sel(at).item() == points["outcome"][last]


def test_a_walkers_results_of_map_and_basin_pickle():
    basin = vrw.basin(vrw.Params(model="simplest"), nx=2, ny=2, max_steps=5)
    gait_map = vrw.map(vrw.Params(model="compass"), x="slope", x_range=(0.05, 0.06), nx=2, y="hip_mass",
                       y_range=(9.0, 10.0), ny=2)
    for result in (basin, gait_map):
        again = pickle.loads(pickle.dumps(result))
        assert same(again, result), type(result)


#: Small, quick options of the animations compared.
QUICK = {"fps": 10, "width": 320, "height": 180}


def quick_args():
    return [a for k, v in QUICK.items() for a in (f"--{k}", v)]


@pytest.mark.parametrize("model", ["compass", "telescopic", "models/telescopic.toml"])
def test_animate_draws_a_walkers_run_as_vrw_animate(cli, tmp_path, model):
    model = str(ROOT / model) if model.endswith(".toml") else model
    run = vrw.simulate(vrw.Params(model=model), steps=2)
    cli("simulate", "--model", model, "--steps", 2, "--out", tmp_path)
    cli("animate", tmp_path, *quick_args())
    data = vrw.animate(run, tmp_path / "python.gif", **QUICK).read_bytes()
    assert data.startswith(b"GIF89a") and data == (tmp_path / "walk.gif").read_bytes()
    cli("animate", tmp_path, "--still", 0.4, "--width", 320, "--height", 180)
    png = vrw.animate(run, tmp_path / "python.png", still=0.4, width=320, height=180).read_bytes()
    assert png == (tmp_path / "walk-frame.png").read_bytes()
    # A run rebuilt from its fields alone walks again from its initial state (a described walker's names no
    # file: its model is the description's name).
    if not model.endswith(".toml"):
        assert vrw.animate(vrw.Run(dict(run)), tmp_path / "again.gif", **QUICK).read_bytes() == data
    else:
        with pytest.raises(ValueError, match="does not say which file describes it"):
            vrw.animate(vrw.Run(dict(run)))


def test_animate_draws_a_walkers_gait_from_its_fixed_point(cli, tmp_path):
    params = vrw.Params(model="simplest", slope=0.009)
    gait = vrw.find_gait(params)
    data = vrw.animate(gait, tmp_path / "gait.gif", **QUICK).read_bytes()
    # Two periods (7.8 model time units: more than 2) from the fixed point, as `vrw simulate --initial`.
    section = ",".join(repr(v) for v in gait["section"].values())
    cli("simulate", "--model", "simplest", "--set", "slope=0.009", "--steps", 2, "--initial", section,
        "--out", tmp_path / "walk")
    cli("animate", tmp_path / "walk", *quick_args())
    assert data == (tmp_path / "walk" / "walk.gif").read_bytes()
    assert vrw.animate(vrw.GaitResult(dict(gait)), tmp_path / "again.gif", **QUICK).read_bytes() == data
    with pytest.raises(ValueError, match="found no gait"):
        vrw.animate(vrw.GaitResult(model="compass", status="fell", message="the walker fell"))


def test_a_grid_of_sweeps_takes_a_walker():
    from vrw.grid import gait_grid, orbit_grid

    p = vrw.Params(model="compass")
    x = vrw.linspace(0.05, 0.06, 3)
    grid = gait_grid(None, p, x=("slope", x), y=("hip_mass", [8.0, 10.0]))
    for i, hip_mass in enumerate([8.0, 10.0]):
        row = vrw.sweep(p.replace(hip_mass=hip_mass), "slope", x)
        assert np.array_equal(grid["sweep"]["period"][i], row["sweep"]["period"])
    with pytest.raises(vrw.ConfigError, match="model `compass`"):
        orbit_grid(None, p, "slope", range=(0.05, 0.06), points=3)


# --- Figures and docs -----------------------------------------------------------------------------------


def test_vrw_plot_draws_a_walkers_sweep_orbit_and_run():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import vrw.plot

    p = vrw.Params(model="compass")
    sweep = vrw.sweep(p, "slope", vrw.linspace(0.07, 0.08, 6))
    axes = vrw.plot.sweep(sweep)
    assert len(axes) == 3 and axes[-1].get_xlabel() != ""
    assert len(vrw.plot.sweep(vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(40, 60, 3)))) == 3
    with pytest.raises(ValueError, match="model `compass`"):
        vrw.plot.fig2(sweep)
    diagram = vrw.orbit(p, "slope", range=(0.07, 0.08), points=5, transient=10, steps=8)
    assert vrw.plot.orbit(diagram)[0].get_ylabel() != ""
    run = vrw.simulate(p, steps=3)
    assert len(vrw.plot.run(run)) == len(run["coordinates"]) + 1
    with pytest.raises(ValueError, match="model `compass`"):
        vrw.plot.steps(run)
    import matplotlib.pyplot as plt

    plt.close("all")


def test_the_package_docstring_runs():
    failed, attempted = doctest.testmod(vrw)
    assert attempted >= 6 and failed == 0
