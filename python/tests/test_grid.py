"""vrw.grid on a dask.distributed LocalCluster with worker processes: the gait grid, the map's gaits and the
basin equal the serial jobs bit for bit, also when a worker is killed mid-run."""

import json
import os
import pickle
import signal
import threading
import time

import numpy as np
import pytest

import vrw
from vrw.grid import basin_grid, gait_grid, map_grid, orbit_grid

distributed = pytest.importorskip("dask.distributed")


def test_grid_on_local_cluster_equals_serial():
    params = vrw.Params()
    k = params["stiffness"]
    x = ("viscosity", [30.0, 45.0, 60.0])
    y = ("stiffness", [0.9 * k, 1.1 * k])
    serial = gait_grid(None, params, x=x, y=y)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        parallel = gait_grid(client, params, x=x, y=y)
        workers = client.run(lambda: __import__("os").getpid())
    assert len(set(workers.values())) == 2
    assert serial["sweep"].keys() == parallel["sweep"].keys()
    for name, column in serial["sweep"].items():
        assert column.shape == (2, 3), name
        assert column.dtype == parallel["sweep"][name].dtype, name
        assert column.tobytes() == parallel["sweep"][name].tobytes(), name
    assert json.dumps(serial["thresholds"]) == json.dumps(parallel["thresholds"])
    assert serial["gaits_found"] == parallel["gaits_found"]
    # Each row is the sweep of x at that y.
    row = vrw.sweep(params.replace(stiffness=y[1][1]), "viscosity", x[1])
    assert row["sweep"]["lambda_4_plus"].tobytes() == serial["sweep"]["lambda_4_plus"][1].tobytes()
    assert pickle.loads(pickle.dumps(serial)).keys() == serial.keys()
    assert np.array_equal(serial["y_values"], y[1])


def assert_same_result(serial, parallel, table):
    """Two results of a job are the same: every field, and every column of `table` byte for byte."""
    assert serial.keys() == parallel.keys()
    for key in serial:
        if key == table:
            assert list(serial[key].keys()) == list(parallel[key].keys())
            for name, column in serial[key].items():
                other = parallel[key][name]
                assert (column.dtype, column.shape) == (other.dtype, other.shape), name
                assert column.tobytes() == other.tobytes(), name
        else:
            assert json.dumps(serial[key], default=str) == json.dumps(parallel[key], default=str), key


MAP = dict(x_range=(30.0, 70.0), y_range=(440.0, 560.0), nx=7, ny=5)
BASIN = dict(nx=6, ny=7, max_steps=20)
# Values past the gait's end (walks that roll back) and a last interval of two values.
ORBIT = dict(range=(100.0, 180.0), points=23, transient=8, steps=8)


@pytest.mark.parametrize("rows_per_task", [1, 2, 5])
def test_map_and_basin_in_parts_equal_the_whole_jobs(rows_per_task):
    params = vrw.Params()
    assert_same_result(
        vrw.map(params, curves=False, **MAP), map_grid(None, params, rows_per_task=rows_per_task, **MAP), "map"
    )
    assert_same_result(
        vrw.basin(params, **BASIN), basin_grid(None, params, rows_per_task=rows_per_task, **BASIN), "points"
    )


@pytest.mark.parametrize("branch", [True, False])
def test_orbit_in_parts_equals_the_whole_job(branch):
    params = vrw.Params()
    serial = vrw.orbit(params, branch=branch, **ORBIT)
    assert set(serial["outcomes"]) == {"period_1", "rolled_back"}
    parts = orbit_grid(None, params, branch=branch, **ORBIT)
    assert_same_result(serial, parts, "orbit")
    if branch:
        assert_same_result({"branch": serial["branch"]}, {"branch": parts["branch"]}, "branch")


def test_parts_are_checked():
    params = vrw.Params()
    with pytest.raises(vrw.ConfigError, match="curves need every row"):
        map_grid(None, params, curves=True, **MAP)
    with pytest.raises(vrw.ConfigError, match="rows_per_task"):
        basin_grid(None, params, rows_per_task=0, **BASIN)
    with pytest.raises(vrw.ConfigError, match="within 0..5"):
        vrw.map(params, curves=False, rows=(3, 6), **MAP)
    with pytest.raises(vrw.ConfigError, match="no curves"):
        vrw.map(params, rows=(0, 1), **MAP)
    with pytest.raises(vrw.ConfigError, match="within 0..7"):
        vrw.basin(params, rows=(2, 2), **BASIN)
    with pytest.raises(vrw.ConfigError, match="intervals"):
        vrw.orbit(params, part=("fill", 3, None), **ORBIT)
    with pytest.raises(vrw.ConfigError, match="for `part`"):
        vrw.orbit(params, part="middle", **ORBIT)
    # An invalid option is the library's error, raised before any task is submitted.
    with pytest.raises(vrw.ConfigError, match="ny"):
        map_grid(None, params, **dict(MAP, ny=0))


def test_map_and_basin_on_a_local_cluster_survive_a_killed_worker():
    """A worker killed while it holds tasks of a map: its tasks are recomputed elsewhere, the map is still the
    serial one bit for bit; the restarted cluster then computes a basin and an orbit diagram in parts."""
    params = vrw.Params()
    big_map = dict(MAP, nx=60, ny=9)  # rows of about half a second each
    serial_map = vrw.map(params, curves=False, **big_map)
    serial_basin = vrw.basin(params, **BASIN)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        pids = client.run(os.getpid)
        killed = {}

        def kill_a_busy_worker():
            # Wait until a worker holds a task, then kill its process (the nanny starts a new one).
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline:
                busy = [w for w, tasks in client.processing().items() if tasks]
                if busy:
                    time.sleep(0.2)
                    killed["pid"] = pids[busy[0]]
                    killed["tasks"] = len(client.processing()[busy[0]])
                    os.kill(killed["pid"], signal.SIGKILL)
                    return
                time.sleep(0.02)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        parallel_map = map_grid(client, params, **big_map)
        killer.join()
        assert "pid" in killed, "no worker was busy"
        assert killed["tasks"] > 0
        client.wait_for_workers(2, timeout=60)
        assert killed["pid"] not in client.run(os.getpid).values()
        parallel_basin = basin_grid(client, params, rows_per_task=2, **BASIN)
        parallel_orbit = orbit_grid(client, params, **ORBIT)
    assert_same_result(serial_map, parallel_map, "map")
    assert_same_result(serial_basin, parallel_basin, "points")
    serial_orbit = vrw.orbit(params, **ORBIT)
    assert_same_result(serial_orbit, parallel_orbit, "orbit")
    assert_same_result({"branch": serial_orbit["branch"]}, {"branch": parallel_orbit["branch"]}, "branch")
