#pragma once
// Pseudo-arclength continuation of the solutions of F(x; lambda) = 0 (n
// equations, n unknowns x, one driving parameter lambda), passing through
// folds, with step control and test functions for fold and Hopf points
// (Keller's method as in AUTO-07p / MatCont; docs/user_guide.md, "Continuation through folds").
//
// Scaled variables y = [x / x_scale; lambda / lambda_scale]. From a solution
// y_k with unit tangent t_k (the null vector of the scaled Jacobian
// [F_x F_lambda], oriented like t_{k-1}), the predictor y_k + ds t_k /
// lambda_scale is corrected on
//     F(x; lambda) = 0,   t_k . (y - y_k) = ds / lambda_scale
// by quasi-Newton iterations (the Jacobian at y_k, which its tangent needed,
// with Broyden's rank-one updates: one residual per iteration); a step they
// do not converge on is retried by Newton with a fresh Jacobian at every
// iteration before it counts as failed. Arclength s is measured in the unit
// of lambda: s^2 = sum (dx_i / x_scale_i)^2 lambda_scale^2 + dlambda^2, so
// |dlambda| <= ds always. Step control: the step grows (x1.5, up to
// max_step) after a corrector of at most fast_iterations (2 fast_iterations
// for the quasi-Newton one), halves on a failed corrector; below min_step
// the continuation throws an Error naming it.
//
// Test functions between consecutive points:
//   fold  tau = t_lambda, the lambda component of the unit tangent (equal in
//         sign to det [F_x F_lambda; t^T] along an oriented branch): a sign
//         change brackets a fold (limit point) of lambda;
//   Hopf  psi = max real part of the eigenvalues with |imag| > hopf_min_imag
//         (a complex-conjugate pair crossing the imaginary axis).
// Each bracket is narrowed by the Illinois (safeguarded secant) method in the
// arclength from its first point until it is at most `location_tolerance`
// long (key's unit), so the reported parameter lies within
// location_tolerance of the test function's root.
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace vdyn {

/// The system continued. residual and jacobian are required; eigenvalues is
/// optional (no stability labels and no Hopf test without it).
struct ArclengthSystem {
  Eigen::VectorXd x_scale;  ///< typical sizes of x (> 0), their units
  double lambda_scale = 1;  ///< typical size of lambda (> 0), its unit
  Eigen::VectorXd r_scale;  ///< equation weights of the corrector's solve (> 0; empty: 1)
  /// F(x; lambda), n values.
  std::function<Eigen::VectorXd(const Eigen::VectorXd& x, double lambda)> residual;
  /// [dF/dx, dF/dlambda] (n x (n + 1)) at (x, lambda) with r = F(x; lambda).
  std::function<Eigen::MatrixXd(const Eigen::VectorXd& x, double lambda, const Eigen::VectorXd& r)> jacobian;
  /// True when r = F meets the solver's tolerances.
  std::function<bool(const Eigen::VectorXd& r)> converged;
  /// Eigenvalues of the linearised dynamics at a solution (1/s).
  std::function<std::vector<std::complex<double>>(const Eigen::VectorXd& x, double lambda)> eigenvalues;
};

struct ArclengthPoint;

struct ArclengthOptions {
  double step = 0.01;             ///< first arclength step, lambda's unit (> 0)
  double min_step = 1e-6;         ///< smallest step before the continuation fails, lambda's unit
  double max_step = 0.1;          ///< largest step, lambda's unit
  int direction = +1;             ///< initial sign of dlambda
  int max_points = 200;           ///< points after the start
  double lambda_min = -1e300, lambda_max = 1e300;  ///< stop on leaving [lambda_min, lambda_max]
  int max_corrector_iterations = 8;
  /// Quasi-Newton correctors first (the start's Jacobian with Broyden
  /// updates, Newton retrying a step they fail on); false: Newton with a
  /// fresh Jacobian at every iteration only. The points meet the same
  /// tolerances either way.
  bool quasi_newton = true;
  /// A corrector of at most this many iterations grows the step (twice as
  /// many for the quasi-Newton corrector: Broyden's convergence is
  /// superlinear, not quadratic, so the same predictor error takes about
  /// twice the iterations, each one residual instead of a Jacobian).
  int fast_iterations = 3;
  double arclength_tolerance = 1e-10;  ///< |t . (y - y_k) - ds| at convergence (scaled units)
  double location_tolerance = 1e-6;    ///< bracket length of a located fold / Hopf point, lambda's unit
  int max_location_iterations = 40;
  double hopf_min_imag = 1e-3;    ///< |imag| of a complex pair, 1/s
  double stability_tolerance = 1e-6;   ///< stable when every real part < -tolerance, 1/s
  /// Stop after this many folds were passed (0: never); the points beyond the
  /// last fold up to the stop are kept.
  int stop_after_folds = 0;
  /// Points past the stop_after_folds-th fold before stopping (at least 1:
  /// the point whose test function revealed it).
  int points_after_last_fold = 0;
  /// Called at every accepted point after the start; a non-empty return (the
  /// reason) ends the continuation at that point (kept as the last):
  /// stop_reason "stopped", the reason in ArclengthResult::stop_message.
  std::function<std::string(const ArclengthPoint&)> stop_if;
};

struct ArclengthPoint {
  Eigen::VectorXd x;
  double lambda = 0;
  double s = 0;                   ///< arclength from the start, lambda's unit
  Eigen::VectorXd tangent;        ///< unit tangent in scaled variables (n + 1; last: lambda)
  int corrector_iterations = 0;
  bool have_eigenvalues = false;
  std::vector<std::complex<double>> eigenvalues;  ///< sorted by descending real part
  bool stable = false;            ///< valid with have_eigenvalues
  /// "start", "regular", "fold" or "hopf" (a located special point).
  std::string kind = "regular";
  double fold_test() const { return tangent.size() ? tangent[tangent.size() - 1] : 0.0; }
  double hopf_test(double min_imag) const;  ///< psi (-inf without a complex pair)
};

struct ArclengthSpecialPoint {
  std::string kind;           ///< "fold" or "hopf"
  ArclengthPoint point;
  double bracket_length = 0;  ///< final bracket length, lambda's unit (<= location_tolerance when located)
  bool located = false;
  int location_iterations = 0;
};

struct ArclengthResult {
  std::vector<ArclengthPoint> points;          ///< along the branch, special points not included
  std::vector<ArclengthSpecialPoint> special;  ///< in the order met
  int steps = 0;             ///< accepted steps
  int rejected_steps = 0;    ///< failed correctors (each halved the step)
  int corrector_iterations = 0;  ///< all Newton iterations (location included)
  int jacobians = 0;             ///< system.jacobian calls (one per tangent, more where Newton retried)
  int residual_evaluations = 0;  ///< system.residual calls
  int quasi_newton_fallbacks = 0;  ///< steps the quasi-Newton corrector left to Newton
  std::string stop_reason;   ///< "max_points", "lambda_range", "folds", "stopped" (stop_if)
  std::string stop_message;  ///< stop_if's reason when stopped
};

/// Continues from a solution (x0, lambda0). Throws Error if the start does not
/// meet `converged`, or when the step falls below min_step (the message names
/// min_step, lambda and the last corrector's residual).
ArclengthResult continueArclength(const ArclengthSystem& system, const Eigen::VectorXd& x0, double lambda0,
                                  const ArclengthOptions& options);

}  // namespace vdyn
