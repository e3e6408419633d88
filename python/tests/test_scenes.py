# Python runs equal the `vdyn` program's, bit for bit: summaries of three
# chapter scenes (3, 4, 7), the recorded history and its units.
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import vdyn
from conftest import read_json

# Timings differ between any two runs; every other number must be identical.
TIMING_KEYS = {"wall_time_s", "real_time_factor"}


def assert_same(py, cli, where="summary"):
    if isinstance(cli, dict):
        assert isinstance(py, dict), where
        keys = set(cli) - TIMING_KEYS - {"plots"}
        assert keys == set(py) - TIMING_KEYS - {"plots"}, where
        for k in keys:
            assert_same(py[k], cli[k], f"{where}.{k}")
    elif isinstance(cli, list):
        assert isinstance(py, list) and len(py) == len(cli), where
        for i, (a, b) in enumerate(zip(py, cli)):
            assert_same(a, b, f"{where}[{i}]")
    elif isinstance(cli, float):
        # Bit for bit: summary.json prints doubles in shortest round-trip form.
        assert isinstance(py, float) and py == cli, f"{where}: python {py!r} != cli {cli!r}"
    else:
        assert py == cli, where


@pytest.mark.parametrize("scene", ["scenes/ch3_transient.json", "scenes/quarter_car_sine_road.json",
                                   "scenes/ch7_open_loop.json"])
def test_summary_equals_cli(scene, cli, tmp_path):
    cli("run", scene, "--out", str(tmp_path), "--no-plots")
    expected = read_json(tmp_path / "summary.json")
    r = vdyn.Scene.from_file(scene).run()
    assert_same(r.summary, expected)
    # History: the CLI's history.csv (17 significant digits) read back exactly.
    table = np.loadtxt(tmp_path / "history.csv", delimiter=",", skiprows=1, ndmin=2)
    with open(tmp_path / "history.csv") as f:
        header = f.readline().strip().split(",")
    assert list(r.history) == header
    for i, name in enumerate(header):
        assert np.array_equal(r.history[name], table[:, i]), name


def test_set_equals_cli_set(cli, tmp_path):
    # The same override through `--set` and Scene.set.
    cli("run", "scenes/ch7_open_loop.json", "--out", str(tmp_path), "--no-plots",
        "--set", "plugins.front_steer.command.final_rad=0.03", "--set", "analysis.t_end_s=4")
    expected = read_json(tmp_path / "summary.json")
    s = vdyn.Scene.from_file("scenes/ch7_open_loop.json")
    s.set("plugins.front_steer.command.final_rad", 0.03).set("analysis.t_end_s", 4)
    assert_same(s.run().summary, expected)
    assert s.json["analysis"]["t_end_s"] == 4


def test_history_length_and_units():
    s = vdyn.Scene.from_file("scenes/quarter_car_sine_road.json")
    r = s.run()
    # t_end_s = 1 s sampled every 0.002 s from t = 0: 501 samples.
    t_end, dt = s.json["analysis"]["t_end_s"], s.json["analysis"]["report_interval_s"]
    n = round(t_end / dt) + 1
    assert n == 501
    assert set(r.history) == {"t_s", *s.json["outputs"]}
    for name, column in r.history.items():
        assert column.dtype == np.float64 and column.shape == (n,), name
    assert r.history["t_s"][0] == 0.0 and r.history["t_s"][-1] == pytest.approx(t_end, abs=1e-12)
    assert np.allclose(np.diff(r.history["t_s"]), dt, rtol=0, atol=1e-12)
    # Units from the scene's outputs; each name ends in its unit.
    assert r.units["t_s"] == "s"
    assert r.units["chassis.z_m"] == "m"
    assert r.units["chassis.az_m_s2"] == "m/s^2"
    assert r.units["tire.Fz_N"] == "N"
    for name in r.history:
        assert name in r.units, name
    # Summary statistics computed from the same samples.
    az = r.history["chassis.az_m_s2"]
    assert r.summary["peak_abs"]["chassis.az_m_s2"] == np.max(np.abs(az))
    assert r.summary["rms"]["chassis.az_m_s2"] == pytest.approx(math.sqrt(np.mean(az * az)), rel=1e-14)


def test_run_writes_files_only_when_asked(tmp_path):
    os.chdir(tmp_path)
    s = vdyn.Scene.from_file("scenes/ch7_open_loop.json").set("analysis.t_end_s", 1.0)
    s.run()
    assert os.listdir(tmp_path) == []
    s.run(out=str(tmp_path / "out"), plots=False)
    assert sorted(os.listdir(tmp_path / "out")) == ["history.csv", "summary.json"]


def test_done_criterion_one_liner(cli, tmp_path, root):
    # The user guide's command (docs/user_guide.md, "Python"), from another working folder (scenes resolve along the data path).
    cli("run", "scenes/ch3_transient.json", "--out", str(tmp_path), "--no-plots")
    expected = read_json(tmp_path / "summary.json")["final"]["chassis.yaw_rate_rad_s"]
    code = ("import vdyn; print(vdyn.Scene.from_file('scenes/ch3_transient.json').run()"
            ".summary['final']['chassis.yaw_rate_rad_s'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=tmp_path).stdout.strip()
    assert float(out) == expected and out == repr(expected)
