# The examples in examples/python run, and their numbers hold: the optimiser
# converges and vdyn's gradient (mixed method) agrees with fd_central to 1e-6.
import importlib.util
import os

import numpy as np
import pytest


def load(root, name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(root, "examples", "python", name + ".py"))
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    return m


def test_optimise_spring(root):
    pytest.importorskip("scipy")  # .ci/install-deps installs python3-scipy; CI runs this
    res, k, g_mixed, g_fd = load(root, "optimise_spring").main()
    assert res.success
    assert abs(g_mixed - g_fd) <= 1e-6 * abs(g_fd)


def test_sweep_example(root):
    rows = load(root, "sweep").main()
    assert rows["ok"].all() and len(rows["variation"]) == 9
    yaw = rows["final.chassis.yaw_rate_rad_s"].reshape(3, 3)
    assert (np.diff(yaw, axis=0) > 0).all()  # more steer, more yaw rate at every speed


def test_turn_over_speed(root, tmp_path):
    yaw = load(root, "turn_over_speed").main(str(tmp_path))
    assert (tmp_path / "turn_over_speed.csv").exists() and len(yaw) == 6 and (yaw > 0).all()
