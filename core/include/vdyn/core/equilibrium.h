#pragma once
// Static equilibrium of a scene: all generalized speeds zero and every
// generalized force balanced. Formulated as the seed's steady-state equations
// with zero velocities (3.9)-(3.13): unknowns are the coordinates q of every
// mobilizer not declared ineffective (Euler angles in place of quaternions)
// and the multipliers lambda of the position constraints; equations are the
// force residual  f - M udot - G^T lambda  at udot = 0 (Simbody's inverse
// dynamics) and the position-constraint errors Psi(q) = 0. Newton-Raphson with
// a finite-difference Jacobian and a backtracking line search; where it fails,
// Levenberg-Marquardt on the weighted residual (globalised: every step lowers
// the merit), which stops at a minimum of the residual that is not a root and
// says so (no equilibrium near the start, e.g. past a fold).
#include <vector>

#include "vdyn/core/scene.h"

namespace vdyn {

struct StaticEquilibriumOptions {
  /// Convergence on the generalized-force residual, N (or N m). About 1e-15 of a
  /// 1.5e5 N/m tire's stiffness times its radius; tighter is below round-off.
  double force_tolerance = 1e-6;
  /// Convergence on the position-constraint errors, m (or rad).
  double constraint_tolerance = 1e-12;
  /// Newton iterations (the first try), >= 0.
  int max_iterations = 50;
  /// Weight of constraint rows in the merit (line search and Levenberg-Marquardt), N/m.
  double constraint_weight = 1e6;
  /// Levenberg-Marquardt iterations after Newton fails; 0 = no fallback.
  int trust_region_iterations = 500;
  /// Initial Levenberg-Marquardt damping, relative to diag(J^T J) (dimensionless).
  double trust_region_initial_damping = 1e-3;
  /// A point is a stationary point of the merit (not a root) when
  /// |J^T r| <= this * |J| |r| (weighted rows; dimensionless).
  double stationary_tolerance = 1e-10;
};

struct StaticEquilibriumResult {
  int iterations = 0;             ///< Newton plus Levenberg-Marquardt iterations
  int newton_iterations = 0;      ///< of the first try
  int trust_region_iterations = 0;  ///< of the Levenberg-Marquardt fallback (0 if Newton converged)
  double force_residual = 0;     ///< max |generalized-force residual| at the solution
  double constraint_error = 0;   ///< max |qerr| at the solution
  SimTK::Vector multipliers;     ///< lambda of the position constraints
  /// Generalized-force residual f - M udot - G^T lambda for every mobility
  /// (zero for the unknowns; for ineffective mobilizers, their imbalance), N or N m.
  SimTK::Vector force_residual_all;
};

/// Solves for the static equilibrium and updates `state` (u set to zero). The
/// coordinates of `ineffective` mobilizers (e.g. wheel spin) keep their values
/// and their force balance is not enforced (it holds trivially at rest, or the
/// caller knows it is neutral). Only holonomic constraints are supported.
/// Throws Error reporting iterations, residuals and the worst equation if it
/// does not converge.
StaticEquilibriumResult solveStaticEquilibrium(const Scene& scene, SimTK::State& state,
                                               const std::vector<SimTK::MobilizedBodyIndex>& ineffective,
                                               const StaticEquilibriumOptions& options = {});

}  // namespace vdyn
