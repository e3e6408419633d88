#include "vdyn/core/stiffness.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "vdyn/core/error.h"

namespace vdyn {

void calcStateDerivativeJacobianColumns(const SimTK::System& system, SimTK::State& work, const SimTK::Vector& f0,
                                        double* const* columns, long* evaluations) {
  const int nq = work.getNQ(), nu = work.getNU(), nz = work.getNZ();
  system.realize(work, SimTK::Stage::Velocity);
  // One column: y_j moved by dy (its Simbody stage's cache and those below
  // stay valid), the accelerations realized, y_j put back.
  auto column = [&](double& yj, int j) {
    const double y0 = yj, dy = 1e-7 * std::max(std::abs(y0), 1e-2);
    yj = y0 + dy;
    system.realize(work, SimTK::Stage::Acceleration);
    const SimTK::Vector& f = work.getYDot();
    double* col = columns[j];
    for (int i = 0; i < f.size(); ++i) col[i] = (f[i] - f0[i]) / dy;
    // Restored through upd*, which invalidates the stages that depend on it.
    return y0;
  };
  // z first (their change invalidates only Dynamics), then u (Velocity),
  // then q (Position): each column recomputes only its own stages and up.
  for (int k = 0; k < nz; ++k) {
    const double z0 = column(work.updZ()[k], nq + nu + k);
    work.updZ()[k] = z0;
  }
  for (int k = 0; k < nu; ++k) {
    const double u0 = column(work.updU()[k], nq + k);
    work.updU()[k] = u0;
  }
  for (int k = 0; k < nq; ++k) {
    const double q0 = column(work.updQ()[k], k);
    work.updQ()[k] = q0;
  }
  if (evaluations) *evaluations += nq + nu + nz;
}

Eigen::MatrixXd calcStateDerivativeJacobian(const SimTK::System& system, const SimTK::State& at, long* evaluations) {
  SimTK::State w = at;
  system.realize(w, SimTK::Stage::Acceleration);
  const int n = w.getNY();
  const SimTK::Vector f0 = w.getYDot();
  Eigen::MatrixXd J(n, n);
  std::vector<double*> columns(n);
  for (int j = 0; j < n; ++j) columns[j] = J.data() + std::ptrdiff_t(j) * n;
  calcStateDerivativeJacobianColumns(system, w, f0, columns.data(), evaluations);
  if (evaluations) ++*evaluations;
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

Eigen::VectorXd calcModeShape(const Eigen::MatrixXd& jacobian, std::complex<double> lambda) {
  if (!jacobian.allFinite()) throw Error("stiffness: the Jacobian of the state derivative has a non-finite entry");
  const Eigen::Index n = jacobian.rows();
  // Shifted off the eigenvalue by a relative 1e-10 so that the LU has no
  // exact zero pivot; the solve then amplifies the eigenvector by ~1e10.
  const std::complex<double> mu = lambda + 1e-10 * std::max(1.0, std::abs(lambda));
  Eigen::MatrixXcd A = jacobian.cast<std::complex<double>>();
  A.diagonal().array() -= mu;
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(A);
  Eigen::VectorXcd x = Eigen::VectorXcd::Ones(n);
  for (int k = 0; k < 2; ++k) {
    x = lu.solve(x);
    const double m = x.cwiseAbs().maxCoeff();
    if (!(m > 0) || !std::isfinite(m)) return Eigen::VectorXd::Zero(n);
    x /= m;
  }
  return x.cwiseAbs();
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
  // Largest |lambda| first: R is stable on the left half-disk |z| <= 1
  // (kStableRadius, tests/test_core.cpp scans it), so an eigenvalue with
  // 1 / |lambda| above the smallest limit so far cannot set a smaller one,
  // nor can any after it.
  constexpr double kStableRadius = 1.0;
  std::vector<std::size_t> order(eigenvalues.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return std::abs(eigenvalues[a]) > std::abs(eigenvalues[b]); });
  std::vector<double> h(eigenvalues.size(), std::numeric_limits<double>::infinity());
  for (const std::size_t i : order) {
    const std::complex<double> lambda = eigenvalues[i];
    const double mag = std::abs(lambda);
    if (!(lambda.real() < 0) || !(mag > 0)) continue;
    if (kStableRadius / mag > hMin) break;
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
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (lo + hi);
      (stable(mid) ? lo : hi) = mid;
    }
    h[i] = lo / mag;
    hMin = std::min(hMin, h[i]);
  }
  // The limiting eigenvalue: the first in the given order that sets the limit.
  if (limiting)
    for (std::size_t i = 0; i < h.size(); ++i)
      if (h[i] == hMin) {
        *limiting = eigenvalues[i];
        break;
      }
  return hMin;
}

}  // namespace vdyn
