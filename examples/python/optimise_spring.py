"""The quarter car's spring stiffness K minimising psi = int_0^1 z''^2 dt (seed
4.46) on the 0.02 m, 3 Hz sine road, with scipy.optimize on vdyn's gradient
(the seed's mixed method, 4.23-4.44), checked against fd_central (4.22).

    PYTHONPATH=build/python python3 examples/python/optimise_spring.py
"""
import sys

import vdyn

SCENE = "scenes/ch4_sensitivity.json"
K_PATH = "vehicle.data.corner_overrides.spring.stiffness_N_per_m"
BOUNDS_N_PER_M = (5e3, 8e4)


def psi_and_gradient(k_N_per_m, method="mixed"):
    """psi (m^2/s^3) and d psi / d K (m^2/s^3 per N/m) at spring stiffness K."""
    s = vdyn.Scene.from_file(SCENE)
    s.set("vehicle.overrides.corner_overrides", {"spring": {"stiffness_N_per_m": float(k_N_per_m)}})
    s.set("analysis.parameters", [{"path": K_PATH, "name": "K", "symbol": "K", "unit": "N/m", "scale": 1e4}])
    s.set("analysis.derived_data", "each_design")  # psi(K) as the optimiser sees it: free length re-derived
    s.set("analysis.methods", [method])
    r = s.run().summary
    return r["psi"], r["methods"][method]["dpsi_db"][0]


def main():
    from scipy.optimize import minimize
    scale = 1e4  # K in units of 1e4 N/m for the optimiser
    f = lambda x: tuple(v * (scale if i else 1) for i, v in enumerate(psi_and_gradient(x[0] * scale)))
    res = minimize(f, x0=[2.0], jac=True, method="L-BFGS-B",
                   bounds=[(BOUNDS_N_PER_M[0] / scale, BOUNDS_N_PER_M[1] / scale)], options={"ftol": 1e-12})
    k = res.x[0] * scale
    psi, g_mixed = psi_and_gradient(k, "mixed")
    _, g_fd = psi_and_gradient(k, "fd_central")
    rel = abs(g_mixed - g_fd) / max(abs(g_fd), 1e-300)
    print(f"converged: {res.success} ({res.message}), {res.nit} iterations, {res.nfev} evaluations")
    print(f"K* = {k:.6g} N/m, psi = {psi:.10g} m^2/s^3")
    print(f"dpsi/dK at K*: mixed {g_mixed:.10g}, fd_central {g_fd:.10g}, relative difference {rel:.3g}")
    return res, k, g_mixed, g_fd


if __name__ == "__main__":
    res, *_ = main()
    sys.exit(0 if res.success else 1)
