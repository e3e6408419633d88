"""The seed's chapter 3 turn (4 deg front, 1 deg rear, section 3.3) over speed:
the steady yaw rate and path curvature at the end of each transient run.
Plot turn_over_speed.png with matplotlib if installed, else only the CSV.

    PYTHONPATH=build/python python3 examples/python/turn_over_speed.py [OUT_DIR]
"""
import os
import sys

import numpy as np

import vdyn

SPEEDS_M_S = [6.0, 8.0, 10.0, 12.0, 14.0, 16.0]


def turn_at(speed_m_s, t_end_s=10.0):
    s = vdyn.Scene.from_file("scenes/ch3_transient.json")
    s.set("vehicle.initial_speed_m_s", speed_m_s).set("plugins.speed_hold.speed_m_s", speed_m_s)
    s.set("analysis.t_end_s", t_end_s)
    r = s.run()
    return r.summary["final"]["chassis.yaw_rate_rad_s"], r.history


def main(out="results/python_turn_over_speed"):
    os.makedirs(out, exist_ok=True)
    yaw = np.array([turn_at(v)[0] for v in SPEEDS_M_S])
    curvature = yaw / np.array(SPEEDS_M_S)  # 1/m
    np.savetxt(os.path.join(out, "turn_over_speed.csv"), np.column_stack([SPEEDS_M_S, yaw, curvature]),
               delimiter=",", header="speed_m_s,yaw_rate_rad_s,curvature_1_per_m", comments="")
    for v, r, c in zip(SPEEDS_M_S, yaw, curvature):
        print(f"{v:5.1f} m/s: yaw rate {r:.6f} rad/s, curvature {c:.6f} 1/m")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no plot (the CSV is written)")
        return yaw
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
    ax[0].plot(SPEEDS_M_S, yaw, "o-")
    ax[0].set(xlabel="speed (m/s)", ylabel="steady yaw rate (rad/s)")
    ax[1].plot(SPEEDS_M_S, curvature, "o-")
    ax[1].set(xlabel="speed (m/s)", ylabel="path curvature (1/m)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "turn_over_speed.png"), dpi=120)
    return yaw


if __name__ == "__main__":
    main(*sys.argv[1:])
