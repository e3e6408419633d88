"""A sweep from Python: the bicycle's step steer (chapter 7) over steer angle
and speed on two C++ threads; the rows as NumPy arrays (a pandas DataFrame if
pandas is installed).

    PYTHONPATH=build/python python3 examples/python/sweep.py
"""
import vdyn

SWEEP = {
    "scene": "scenes/ch7_open_loop.json",
    "set": {"analysis.t_end_s": 5.0},
    "variations": [{"grid": [
        {"key": "plugins.front_steer.command.final_rad", "from": 0.01, "to": 0.05, "count": 3},
        {"keys": ["vehicle.initial_speed_m_s", "plugins.speed_hold.speed_m_s"], "values": [[8, 8], [12, 12], [16, 16]]}]}],
    "collect": ["final.chassis.yaw_rate_rad_s", "peak_abs.chassis.side_slip_rad"],
}


def main():
    rows = vdyn.sweep(SWEEP, threads=2)
    try:
        import pandas
        print(pandas.DataFrame({k: v for k, v in rows.items() if k != "reason"}))
    except ImportError:
        for i in rows["variation"]:
            print(i, rows["plugins.front_steer.command.final_rad"][i], rows["vehicle.initial_speed_m_s"][i],
                  rows["final.chassis.yaw_rate_rad_s"][i])
    return rows


if __name__ == "__main__":
    main()
