# vdyn.sweep (the C++ thread runner), vdyn.tire, vdyn.list and
# vdyn.load_plugin against the `vdyn` program.
import json
import math
import subprocess

import numpy as np
import pytest

import vdyn
from conftest import read_json

SWEEP = {
    "scene": "scenes/ch7_open_loop.json",
    "set": {"analysis.t_end_s": 3.0},
    "variations": [{"grid": [{"key": "plugins.front_steer.command.final_rad", "values": [0.02, 0.04, 0.06]},
                             {"keys": ["vehicle.initial_speed_m_s", "plugins.speed_hold.speed_m_s"],
                              "values": [[8, 8], [12, 12]]}]}],
    "collect": ["final.chassis.yaw_rate_rad_s", "peak_abs.chassis.side_slip_rad"],
}


def test_sweep_equals_cli_and_scene_runs(cli, tmp_path):
    f = tmp_path / "s.sweep.json"
    f.write_text(json.dumps(SWEEP))
    # The dict's scene resolves along the data path; the file's from its folder, then the data path.
    cli("sweep", str(f), "--threads", "2", "--out", str(tmp_path / "out"), "--quiet", "--no-plots")
    expected = read_json(tmp_path / "out" / "results.json")
    rows2 = vdyn.sweep(SWEEP, threads=2)
    rows1 = vdyn.sweep(f, threads=1)
    assert list(rows2["variation"]) == list(range(6)) and rows2["ok"].all()
    for k in rows2:
        assert np.array_equal(rows1[k], rows2[k]), k
    yaw = rows2["final.chassis.yaw_rate_rad_s"]
    assert yaw.dtype == np.float64
    # Each row equals a single Scene run with the same overrides, bit for bit.
    s = vdyn.Scene.from_file("scenes/ch7_open_loop.json").set("analysis.t_end_s", 3.0)
    s.set("plugins.front_steer.command.final_rad", 0.04).set("vehicle.initial_speed_m_s", 12)
    s.set("plugins.speed_hold.speed_m_s", 12)
    assert s.run().summary["final"]["chassis.yaw_rate_rad_s"] == yaw[3]
    # And the CLI's results.json (threads=2), row for row, value for value.
    assert [r["variation"] for r in expected["runs"]] == list(rows2["variation"])
    for i, run in enumerate(expected["runs"]):
        assert run["status"] == "ok"
        for key, value in run["set"].items():
            assert rows2[key][i] == value, (i, key)
        for path, value in run["values"].items():
            assert rows2[path][i] == value, (i, path)


def test_sweep_bad_key_is_error():
    bad = dict(SWEEP, variations=[{"list": [{"analysis.t_end_ss": 1}]}])
    with pytest.raises(vdyn.Error) as e:
        vdyn.sweep(bad)
    assert "t_end_ss" in str(e.value)


def test_tire_equals_cli(cli, tmp_path, root):
    tir = f"{root}/vehicles/data/tires/pac2002_185_80R14.tir"
    cli("tire", tir, "--fz", "2000,4000", "--alpha", "-6,0,3", "--kappa", "-0.1,0,0.05", "--gamma", "0,2",
        "--out", str(tmp_path), "--no-plots")
    grid = np.loadtxt(tmp_path / "grid.csv", delimiter=",", skiprows=1)
    with open(tmp_path / "grid.csv") as f:
        cols = f.readline().strip().split(",")
    c = {n: grid[:, i] for i, n in enumerate(cols)}
    f = vdyn.tire(tir, c["Fz_load_N"], c["alpha_rad"], c["kappa"], c["gamma_rad"], vx_m_s=16.7)
    assert f["kind"] == "magic_formula"
    for k in ["Fx_N", "Fy_N", "Fz_N", "Mx_N_m", "My_N_m", "Mz_N_m"]:
        assert np.array_equal(f[k], c[k]), k
    # Broadcasting: a load column against a row of slip angles; Fy < 0 at alpha > 0.
    fz = np.array([[3000.0], [5000.0]])
    alpha = np.radians(np.linspace(-8, 8, 9))
    g = vdyn.tire(tir, fz, alpha)
    assert g["Fy_N"].shape == (2, 9)
    assert (g["Fy_N"][:, alpha > 0] < 0).all() and (g["Fy_N"][:, alpha < 0] > 0).all()
    assert np.allclose(g["Fz_N"], fz * np.ones_like(alpha), rtol=1e-9)


def test_tire_bad_load():
    with pytest.raises(vdyn.Error) as e:
        vdyn.tire("appendix_a.json", [0.0], [0.01])
    assert "fz_N" in str(e.value)


def test_list_is_the_field_tables(cli):
    types = vdyn.list()
    for kind in ["vehicle", "force_element", "constraint", "controller", "analysis"]:
        assert kind in types
    t = {f["key"]: f for f in types["analysis"]["transient"]["fields"]}
    assert t["t_end_s"]["unit"] == "s" and t["report_interval_s"]["unit"] == "s"
    assert "sensitivity_method" in types and "fd_central" in types["sensitivity_method"]
    # Every type and key `vdyn list` prints is there, and no other.
    text = cli("list").stdout
    for kind, entries in types.items():
        for name, info in entries.items():
            assert f"  {name}" in text, name
            for field in info["fields"]:
                assert f"      {field['key']}" in text, (name, field["key"])


def test_load_plugin(fixture_library, tmp_path):
    if not fixture_library:
        pytest.skip("the test plugin library is built with the C++ tests (VDYN_BUILD_TESTS)")
    assert "fixture_push" not in vdyn.list()["force_element"]
    with pytest.raises(vdyn.Error):
        vdyn.load_plugin(str(tmp_path / "no_such_library.so"))
    vdyn.load_plugin(fixture_library)
    assert "fixture_push" in vdyn.list()["force_element"]
