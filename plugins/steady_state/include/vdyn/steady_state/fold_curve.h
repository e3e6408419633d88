#pragma once
// Two-parameter continuation of a fold (limit-point) curve of F(x; p, mu) = 0
// (n equations, n unknowns x, a first parameter p in which the one-parameter
// branch folds, a second parameter mu along which the fold is followed), by
// the minimally augmented system of Govaerts (MatCont's "LP" curve; docs:
// docs/user_guide.md, "Continuation through folds"):
//     F(x; p, mu) = 0,   g(x; p, mu) = 0,
// with g the bordered determinant test function of the scaled Jacobian
// A = diag(r_scale) F_x diag(x_scale):
//     [A  b] [v]   [0]              [A^T c] [w]   [0]
//     [c' 0] [g] = [1],             [b'  0] [g] = [1],
// b, c the left and right singular vectors of A's smallest singular value at
// the start (fixed along the curve). g = 0 exactly where A is singular: a fold
// of the branch in p (and in mu). Its gradient (Govaerts (2000) eq. 4.4.4)
//     dg/dz_j = -w' diag(r_scale) (d F_x / d z_j) diag(x_scale) v,
// z = (x, p, mu), is taken as a mixed second difference of F along v and z_j
// (two residuals a column). The unknowns (x, p) are continued in mu by
// continueArclength (arclength.h), so the curve passes through its own folds
// in mu.
#include <complex>
#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "vdyn/steady_state/arclength.h"

namespace vdyn {

/// The system whose fold curve is followed.
struct TwoParameterSystem {
  Eigen::VectorXd x_scale;  ///< typical sizes of x (> 0), their units
  double p_scale = 1;       ///< typical size of p (> 0), its unit
  double mu_scale = 1;      ///< typical size of mu (> 0), its unit
  Eigen::VectorXd r_scale;  ///< equation weights (> 0; empty: 1)
  /// F(x; p, mu), n values.
  std::function<Eigen::VectorXd(const Eigen::VectorXd& x, double p, double mu)> residual;
  /// [dF/dx, dF/dp] (n x (n + 1)) at (x, p, mu) with r = F(x; p, mu).
  std::function<Eigen::MatrixXd(const Eigen::VectorXd& x, double p, double mu, const Eigen::VectorXd& r)> jacobian;
  /// True when r = F meets the solver's tolerances.
  std::function<bool(const Eigen::VectorXd& r)> converged;
  /// Eigenvalues of the linearised dynamics at a solution (1/s); optional.
  std::function<std::vector<std::complex<double>>(const Eigen::VectorXd& x, double p, double mu)> eigenvalues;
};

struct FoldCurveOptions {
  ArclengthOptions continuation;   ///< in mu's unit (step, min/max step, mu range, points)
  /// |g| at convergence, relative to A's second-smallest singular value at
  /// the start (g has A's scale; its floor is the finite-difference
  /// Jacobian's noise, ~1e-8 relative).
  double g_tolerance = 1e-6;
  /// Steps of the mixed second difference of g's gradient, in the scaled
  /// variables (x / x_scale, p / p_scale, mu / mu_scale).
  double difference_step = 1e-3;
};

/// The bordering of a fold: b, c (unit, n) and the test function's value there.
struct FoldBordering {
  Eigen::VectorXd b, c;
  double smallest_singular_value = 0;  ///< of A at the start
  double second_singular_value = 0;    ///< the next one (a simple fold: well above the smallest)
};

/// The bordered test function g at (x, p, mu) with Jacobian [F_x F_p] J (n x (n + 1)).
double calcFoldTest(const TwoParameterSystem& sys, const FoldBordering& bord, const Eigen::MatrixXd& J,
                    Eigen::VectorXd* v = nullptr, Eigen::VectorXd* w = nullptr);

/// The bordering at a (near-)fold point (x, p, mu): the singular vectors of
/// A's smallest singular value.
FoldBordering makeFoldBordering(const TwoParameterSystem& sys, const Eigen::VectorXd& x, double p, double mu);

/// A point of the fold curve (unpacked from the extended system's point).
struct FoldCurvePoint {
  Eigen::VectorXd x;
  double p = 0, mu = 0;
  double g = 0;                 ///< the test function at the point (~0)
  ArclengthPoint point;         ///< the extended system's point (x = [x; p], lambda = mu)
};

struct FoldCurveResult {
  FoldBordering bordering;
  ArclengthResult continuation;      ///< of the extended system ([x; p] in mu); special points: folds of the curve in mu, Hopf (fold-Hopf) crossings
  std::vector<FoldCurvePoint> points;  ///< the start and every accepted point, in order
  int residual_evaluations = 0;      ///< F evaluations (Jacobians included)
};

/// Continues the fold curve from a fold (x0, p0) of the branch in p at mu0
/// (e.g. a one-parameter continueArclength's located fold). Throws Error if
/// the start does not meet the tolerances (F and g), or the continuation fails.
FoldCurveResult continueFoldCurve(const TwoParameterSystem& sys, const Eigen::VectorXd& x0, double p0, double mu0,
                                  const FoldCurveOptions& options);

}  // namespace vdyn
