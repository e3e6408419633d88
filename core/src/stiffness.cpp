#include "vdyn/core/stiffness.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "vdyn/core/error.h"

namespace vdyn {

Eigen::MatrixXd calcStateDerivativeJacobian(const SimTK::System& system, const SimTK::State& at, long* evaluations) {
  SimTK::State w = at;
  system.realize(w, SimTK::Stage::Acceleration);
  const int n = w.getNY();
  const SimTK::Vector y0 = w.getY();
  const SimTK::Vector f0 = w.getYDot();
  Eigen::MatrixXd J(n, n);
  for (int j = 0; j < n; ++j) {
    const double dy = 1e-7 * std::max(std::abs(y0[j]), 1e-2);
    w.updY() = y0;
    w.updY()[j] += dy;
    system.realize(w, SimTK::Stage::Acceleration);
    const SimTK::Vector& f = w.getYDot();
    for (int i = 0; i < n; ++i) J(i, j) = (f[i] - f0[i]) / dy;
  }
  if (evaluations) *evaluations += n + 1;
  return J;
}

std::vector<std::complex<double>> calcEigenvalues(const Eigen::MatrixXd& jacobian) {
  if (!jacobian.allFinite()) throw Error("stiffness: the Jacobian of the state derivative has a non-finite entry");
  Eigen::EigenSolver<Eigen::MatrixXd> es(jacobian, /*computeEigenvectors=*/false);
  if (es.info() != Eigen::Success)
    throw Error("stiffness: the eigenvalues of the " + std::to_string(jacobian.rows()) + " x " +
                std::to_string(jacobian.cols()) + " Jacobian did not converge");
  const auto& v = es.eigenvalues();
  return std::vector<std::complex<double>>(v.data(), v.data() + v.size());
}

std::complex<double> calcRkMersonStabilityFunction(std::complex<double> z) {
  // The stages of RungeKuttaMersonIntegratorRep::attemptODEStep with h = 1,
  // f(y) = (z / h) y, y0 = 1.
  using C = std::complex<double>;
  const C f0 = z;
  const C f1 = z * (1.0 + f0 / 3.0);
  const C f2 = z * (1.0 + (f0 + f1) / 6.0);
  const C f3 = z * (1.0 + (f0 + 3.0 * f2) / 8.0);
  const C f4 = z * (1.0 + (f0 - 3.0 * f2 + 4.0 * f3) / 2.0);
  return 1.0 + (f0 + 4.0 * f3 + f4) / 6.0;
}

double calcRkMersonStabilityLimit(const std::vector<std::complex<double>>& eigenvalues,
                                  std::complex<double>* limiting) {
  double hMin = std::numeric_limits<double>::infinity();
  for (const auto& lambda : eigenvalues) {
    const double mag = std::abs(lambda);
    if (!(lambda.real() < 0) || !(mag > 0)) continue;
    const std::complex<double> dir = lambda / mag;
    auto stable = [&](double x) { return std::abs(calcRkMersonStabilityFunction(x * dir)) <= 1.0; };
    // The first x = h |lambda| along the ray where |R| exceeds 1: scanned in
    // steps of 0.01 (R's region reaches about 3.5 on the negative real axis
    // and 2.8 along the imaginary one), then bisected.
    double lo = 0, hi = 0;
    for (double x = 0.01; x <= 10.0; x += 0.01) {
      if (!stable(x)) {
        hi = x;
        break;
      }
      lo = x;
    }
    if (hi == 0) continue;  // stable along the whole scanned ray
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo + hi);
      (stable(mid) ? lo : hi) = mid;
    }
    const double h = lo / mag;
    if (h < hMin) {
      hMin = h;
      if (limiting) *limiting = lambda;
    }
  }
  return hMin;
}

}  // namespace vdyn
