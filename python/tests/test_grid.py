"""vrw.grid.gait_grid on a dask.distributed LocalCluster with worker processes equals the serial grid bit
for bit."""

import json
import pickle

import numpy as np
import pytest

import vrw
from vrw.grid import gait_grid

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
