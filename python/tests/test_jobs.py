"""simulate, find_gait and sweep give exactly what the command line writes (compared with its files, not
with numbers of today's physics)."""

import json
import pickle
import threading

import numpy as np
import pytest

import vrw
from conftest import assert_table_equals_csv, cli_error, json_equal, read_csv


def test_simulate_equals_the_command_lines_files(cli, tmp_path):
    cli("simulate", "--steps", 4, "--set", "viscosity=37", "--out", tmp_path)
    run = vrw.simulate(vrw.Params(viscosity=37), steps=4)
    assert_table_equals_csv(run["steps"], tmp_path / "steps.csv")
    assert_table_equals_csv(run["trajectory"], tmp_path / "trajectory.csv")
    summary = json.loads((tmp_path / "summary.json").read_text())
    # Only the command line writes files, and its summary keeps the last steps only (steps.csv has them all);
    # Python returns every step.
    assert summary["files"] == ["steps.csv", "trajectory.csv", "summary.json"] and run["files"] == []
    assert len(run["steps"]["step"]) == run["steps_limit"] == 4
    ignored = ("steps", "trajectory", "files", "steps_limit")
    assert json_equal(
        {k: v for k, v in run.items() if k not in ignored},
        {k: v for k, v in summary.items() if k not in ignored},
    )
    assert run["status"] == "completed"
    assert vrw.simulate(vrw.Params(viscosity=37), steps=4, trajectory=False)["trajectory"] is None


def test_a_reset_walk_has_the_reset_energy_column_of_the_command_line(cli, tmp_path):
    # Stiff legs whose old rear leg is still free at a touchdown: `rear_exit = "reset"` walks on.
    keys = {"viscosity": 28.181818181818183, "stiffness": 1945.4545454545455, "rear_exit": "reset"}
    sets = [a for k, v in keys.items() for a in ("--set", f"{k}={v}")]
    cli("simulate", "--steps", 20, *sets, "--out", tmp_path)
    run = vrw.simulate(vrw.Params(**keys), steps=20, trajectory=False)
    assert list(run["steps"])[-1] == "reset_energy"
    assert_table_equals_csv(run["steps"], tmp_path / "steps.csv")
    assert run["status"] == "completed"
    assert "reset_energy" not in vrw.simulate(vrw.Params(**dict(keys, rear_exit="relock")), steps=2)["steps"]


def test_a_continue_walk_has_the_swinging_leg_columns_of_the_command_line(cli, tmp_path):
    # The same stiff legs under `rear_exit = "continue"`: the free old rear leg swings on as L3 until it locks.
    keys = {"viscosity": 28.181818181818183, "stiffness": 1945.4545454545455, "rear_exit": "continue"}
    sets = [a for k, v in keys.items() for a in ("--set", f"{k}={v}")]
    cli("simulate", "--steps", 20, *sets, "--out", tmp_path)
    run = vrw.simulate(vrw.Params(**keys), steps=20)
    assert run["status"] == "completed"
    assert list(run["trajectory"])[-2:] == ["L3", "L3dot"]
    assert (run["trajectory"]["L3"] > 0).any()
    assert_table_equals_csv(run["trajectory"], tmp_path / "trajectory.csv")
    assert_table_equals_csv(run["steps"], tmp_path / "steps.csv")
    assert "L3" not in vrw.simulate(vrw.Params(**dict(keys, rear_exit="relock")), steps=2)["trajectory"]


def test_a_walk_that_stops_is_a_status(cli, tmp_path):
    # Uphill the wheel cannot walk: it rolls back (whatever the other parameters).
    cli("simulate", "--steps", 3, "--set", "slope=-0.1", "--out", tmp_path, check=False)
    run = vrw.simulate(vrw.Params(slope=-0.1), steps=3)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert run["status"] == summary["status"] != "completed"
    assert run["message"] == summary["message"]
    assert_table_equals_csv(run["steps"], tmp_path / "steps.csv")


def test_invalid_initial_state_raises_the_command_lines_message(cli, tmp_path):
    with pytest.raises(vrw.WalkError) as raised:
        vrw.simulate(vrw.Params(), steps=1, initial=(-1.0, 1.0, 0.0))
    done = cli("simulate", "--steps", 1, "--initial=-1,1,0", "--out", tmp_path, check=False)
    assert str(raised.value) == cli_error(done).removeprefix("simulate: ")


def test_find_gait_equals_gait_json(cli, tmp_path):
    cli("gait", "--set", "viscosity=37", "--out", tmp_path)
    gait = vrw.find_gait(vrw.Params(viscosity=37))
    expected = json.loads((tmp_path / "gait.json").read_text())
    assert json_equal(gait, expected)
    assert gait["status"] == "found"
    assert gait["floquet_multipliers"].dtype == np.complex128
    assert gait["jacobian"].shape == (len(gait["floquet_multipliers"]),) * 2


def test_parameter_derivative_is_the_command_lines(cli, tmp_path):
    cli("gait", "--parameter", "stiffness", "--out", tmp_path)
    gait = vrw.find_gait(vrw.Params(), parameter="stiffness")
    assert json_equal(gait, json.loads((tmp_path / "gait.json").read_text()))
    assert gait["dP_dparam"]["parameter"] == "stiffness"
    assert len(gait["dP_dparam"]["values"]) == 3
    with pytest.raises(vrw.ConfigError, match="parameter"):
        vrw.find_gait(vrw.Params(), parameter="legs")


def test_search_options_are_the_command_lines(cli, tmp_path):
    cli("gait", "--transient", 12, "--tolerance", 1e-11, "--out", tmp_path)
    gait = vrw.find_gait(vrw.Params(), transient_steps=12, tolerance=1e-11)
    assert json_equal(gait, json.loads((tmp_path / "gait.json").read_text()))
    with pytest.raises(TypeError):
        vrw.find_gait(vrw.Params(), transient=12)
    with pytest.raises(ValueError):
        vrw.find_gait(vrw.Params(), tolerance=-1.0)


def test_no_gait_is_a_status_and_reason(cli, tmp_path):
    done = cli("gait", "--set", "slope=-0.1", "--out", tmp_path, check=False)
    assert done.returncode == 1
    gait = vrw.find_gait(vrw.Params(slope=-0.1))
    expected = json.loads((tmp_path / "gait.json").read_text())
    assert gait["status"] != "found" and gait["message"]
    assert json_equal(gait, expected)


def test_sweep_equals_sweep_csv_and_thresholds_json(cli, tmp_path):
    args = ("--from", 1, "--to", 300, "--points", 100)
    cli("sweep", *args, "--out", tmp_path)
    header, rows = read_csv(tmp_path / "sweep.csv")
    values = [float(r[0]) for r in rows]
    assert vrw.linspace(1, 300, 100) == values
    result = vrw.sweep(vrw.Params(), "viscosity", np.array(values))
    assert_table_equals_csv(result["sweep"], tmp_path / "sweep.csv")
    thresholds = json.loads((tmp_path / "thresholds.json").read_text())
    assert json_equal(result["thresholds"], thresholds["thresholds"])
    assert result["gaits_found"] == thresholds["gaits_found"]


def test_results_pickle():
    p = vrw.Params(viscosity=37)
    for result in (vrw.simulate(p, steps=2), vrw.find_gait(p), vrw.sweep(p, "viscosity", [36.0, 37.0])):
        back = pickle.loads(pickle.dumps(result))
        assert back.keys() == result.keys()
        assert repr(back) == repr(result)


def test_computation_releases_the_gil():
    # While a search runs in another thread, this thread runs Python code. With the GIL held through the
    # search, this thread could only resume after it, and would find it done.
    started, done = threading.Event(), threading.Event()

    def search():
        started.set()
        vrw.find_gait(vrw.Params(viscosity=37))
        done.set()

    worker = threading.Thread(target=search)
    worker.start()
    started.wait()
    ran_meanwhile = not done.is_set()
    worker.join()
    assert ran_meanwhile


def test_a_slipping_stance_tip_is_the_fourth_section_coordinate(cli, tmp_path):
    # Just above tan(slope) the stance tip still slips at touchdown: the gait's section has its slip velocity.
    cli("gait", "--set", "friction=0.105", "--out", tmp_path / "gait")
    gait = vrw.find_gait(vrw.Params(friction=0.105))
    assert json_equal(gait, json.loads((tmp_path / "gait" / "gait.json").read_text()))
    section = gait["section"]
    assert gait["section_coordinates"] == ["L2", "thetadot", "L2dot", "slip"] and section["slip"] > 0.05
    assert gait["jacobian"].shape == (4, 4) and gait["signature"].startswith("TD DLS")
    # A walk started there with the four numbers is the command line's with --initial of four numbers.
    start = [section[k] for k in ("L2", "thetadot", "L2dot", "slip")]
    cli("simulate", "--steps", 2, "--initial", ",".join(repr(v) for v in start), "--set", "friction=0.105",
        "--out", tmp_path / "walk")
    run = vrw.simulate(vrw.Params(friction=0.105), steps=2, initial=start)
    assert_table_equals_csv(run["steps"], tmp_path / "walk" / "steps.csv")
    assert abs(run["steps"]["slip"][1] - section["slip"]) < 1e-9
    with pytest.raises(vrw.WalkError, match="5 values given"):
        vrw.simulate(vrw.Params(friction=0.105), steps=1, initial=start + [0.0])
    with pytest.raises(vrw.WalkError, match="slip"):
        vrw.simulate(vrw.Params(), steps=1, initial=start)


def test_a_sweep_with_friction_has_the_slip_and_signature_columns(cli, tmp_path):
    cli("sweep", "--set", "friction=0.6", "--from", 30, "--to", 40, "--points", 3, "--out", tmp_path)
    result = vrw.sweep(vrw.Params(friction=0.6), "viscosity", vrw.linspace(30, 40, 3))
    assert_table_equals_csv(result["sweep"], tmp_path / "sweep.csv")
    header, _ = read_csv(tmp_path / "sweep.csv")
    assert header[-2:] == ["slip", "signature"]
    assert all(s.startswith("TD DLS SLIP2") for s in result["sweep"]["signature"])
    # No gait can exist below tan(slope): a status, at every point.
    low = vrw.sweep(vrw.Params(friction=0.05), "viscosity", [30.0, 40.0])
    assert list(low["sweep"]["status"]) == ["friction_below_slope"] * 2
