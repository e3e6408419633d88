"""vdyn: multibody vehicle dynamics from scene files, in Python.

The same code path as the ``vdyn`` program (docs/user_guide.md, "Python"): a scene run
here gives the CLI's summary bit for bit.

    import vdyn
    r = vdyn.Scene.from_file("scenes/ch3_transient.json").run()
    r.summary["final"]["chassis.yaw_rate_rad_s"]      # rad/s, as summary.json
    r.history["chassis.yaw_rate_rad_s"], r.units["chassis.yaw_rate_rad_s"]

Every user error is a ``vdyn.Error`` with the CLI's one-line message (it
names the file, the key path and the value). Runs release the GIL.
"""
import os as _os

import numpy as _np

import sys as _sys

# The vdyn libraries the module links are made global (RTLD_GLOBAL), as in the
# `vdyn` program: a plugin library (load_plugin) resolves vdyn's symbols from them.
_flags = _sys.getdlopenflags()
_sys.setdlopenflags(_flags | _os.RTLD_GLOBAL)
try:
    from ._vdyn import Error, Result, Scene, load_plugin, resolve_data_path  # noqa: F401,E402
    from . import _vdyn  # noqa: E402
finally:
    _sys.setdlopenflags(_flags)

__all__ = ["Error", "Result", "Scene", "list", "sweep", "tire", "load_plugin", "resolve_data_path"]


def _check(self):
    """Validate the scene as ``vdyn check`` does; raise one vdyn.Error carrying
    every error (``.errors``: one line each, each naming its key path)."""
    errors = self.errors()
    if errors:
        e = Error("\n".join(errors) if len(errors) > 1 else errors[0])
        e.errors = errors
        raise e


Scene.check = _check


def list():  # noqa: A001 (the CLI's name: vdyn list)
    """Every registered type by kind (vehicle, force_element, constraint,
    controller, analysis) and choice family: {kind: {type: {"summary",
    "fields": [{"key", "unit", "default", "meaning", "type"}]}}}, from the
    field tables the loaders read with (what ``vdyn list`` prints)."""
    return _vdyn.list_types()


def sweep(sweep, threads=1, out=None, base_dir=None):
    """Run a sweep (a sweep file's path, or its JSON as a dict) on ``threads``
    C++ threads (GIL released); returns the rows, ordered by variation, as a
    dict of NumPy arrays: "variation", "ok", "status" (results.csv's: "ok",
    a named outcome such as "beyond_fold", or "failed"), every varied key, every
    collected summary path (NaN where a run has no result) and "reason". With ``out`` the CLI's
    files (results.csv, results.json, runs.jsonl) are written there too. A
    dict's "scene" resolves from ``base_dir`` (default: the working folder),
    then along the data search path. ``pandas.DataFrame(rows)`` makes a table."""
    if not isinstance(sweep, dict):
        sweep = _os.fspath(sweep)
    return _vdyn.sweep_rows(sweep, int(threads), "" if out is None else _os.fspath(out),
                            "" if base_dir is None else _os.fspath(base_dir))


def tire(data, fz_N, alpha_rad=0.0, kappa=0.0, gamma_rad=0.0, vx_m_s=16.7):
    """A registered tire on its own in steady state, as ``vdyn tire``: ``data``
    is a .tir file (Magic Formula) or a JSON file with a "tire" block (a vehicle
    data file). Loads (N), slip angles (rad), slip ratios and cambers (rad) are
    broadcast against each other (NumPy rules); returns {"Fx_N", "Fy_N", "Fz_N",
    "Mx_N_m", "My_N_m", "Mz_N_m"} as arrays of the broadcast shape, and "kind".
    Signs: alpha > 0 with the patch sliding to +y, so Fy < 0 there; kappa > 0
    driving (vdyn/tire/tire_model.h)."""
    arrays = _np.broadcast_arrays(*(_np.asarray(x, dtype=float) for x in (fz_N, alpha_rad, kappa, gamma_rad)))
    shape = arrays[0].shape
    flat = [_np.ascontiguousarray(a.ravel()) for a in arrays]
    out = _vdyn.tire_forces(_os.fspath(data), *flat, float(vx_m_s))
    return {k: (v.reshape(shape) if isinstance(v, _np.ndarray) else v) for k, v in out.items()}
