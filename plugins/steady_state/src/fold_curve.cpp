#include "vdyn/steady_state/fold_curve.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "vdyn/core/error.h"

namespace vdyn {

namespace {
Eigen::VectorXd weightsOf(const TwoParameterSystem& sys) {
  const auto n = sys.x_scale.size();
  return sys.r_scale.size() == n ? sys.r_scale : Eigen::VectorXd::Ones(n);
}

/// A = diag(r_scale) F_x diag(x_scale).
Eigen::MatrixXd scaledFx(const TwoParameterSystem& sys, const Eigen::MatrixXd& J) {
  const auto n = sys.x_scale.size();
  return weightsOf(sys).asDiagonal() * J.leftCols(n) * sys.x_scale.asDiagonal();
}
}  // namespace

double calcFoldTest(const TwoParameterSystem& sys, const FoldBordering& bord, const Eigen::MatrixXd& J,
                    Eigen::VectorXd* v, Eigen::VectorXd* w) {
  const auto n = sys.x_scale.size();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = scaledFx(sys, J);
  M.block(0, n, n, 1) = bord.b;
  M.block(n, 0, 1, n) = bord.c.transpose();
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n + 1);
  e[n] = 1;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(M);
  const Eigen::VectorXd vg = lu.solve(e);
  if (v) *v = vg.head(n);
  if (w) *w = M.transpose().partialPivLu().solve(e).head(n);
  return vg[n];
}

FoldBordering makeFoldBordering(const TwoParameterSystem& sys, const Eigen::VectorXd& x, double p, double mu) {
  const Eigen::VectorXd r = sys.residual(x, p, mu);
  const Eigen::MatrixXd A = scaledFx(sys, sys.jacobian(x, p, mu, r));
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto n = A.rows();
  FoldBordering b;
  b.b = svd.matrixU().col(n - 1);
  b.c = svd.matrixV().col(n - 1);
  b.smallest_singular_value = svd.singularValues()[n - 1];
  b.second_singular_value = n > 1 ? svd.singularValues()[n - 2] : 0.0;
  return b;
}

FoldCurveResult continueFoldCurve(const TwoParameterSystem& sys, const Eigen::VectorXd& x0, double p0, double mu0,
                                  const FoldCurveOptions& options) {
  const int n = int(sys.x_scale.size());
  if (!sys.residual || !sys.jacobian || !sys.converged)
    throw Error("fold curve: the system needs residual, jacobian and converged");
  requirePositive(sys.p_scale, "fold curve: p_scale");
  requirePositive(sys.mu_scale, "fold curve: mu_scale");
  requirePositive(options.g_tolerance, "fold curve: g_tolerance");
  requirePositive(options.difference_step, "fold curve: difference_step");
  FoldCurveResult res;
  res.bordering = makeFoldBordering(sys, x0, p0, mu0);
  const FoldBordering& bord = res.bordering;
  const Eigen::VectorXd R = weightsOf(sys);
  int evaluations = 0;
  auto F = [&](const Eigen::VectorXd& x, double p, double mu) {
    ++evaluations;
    return sys.residual(x, p, mu);
  };
  // The last residual's Jacobian [F_x F_p] (the corrector asks for the
  // Jacobian at the point whose residual it just took): one per iterate.
  struct Cached {
    Eigen::VectorXd z;
    double mu = NAN;
    Eigen::MatrixXd J;
  };
  auto cache = std::make_shared<Cached>();
  auto jacobianAt = [&, cache](const Eigen::VectorXd& x, double p, double mu, const Eigen::VectorXd& r) {
    Eigen::VectorXd z(n + 1);
    z.head(n) = x;
    z[n] = p;
    if (cache->mu == mu && cache->z.size() == z.size() && cache->z == z) return cache->J;
    cache->J = sys.jacobian(x, p, mu, r);
    evaluations += n + 1;
    cache->z = z;
    cache->mu = mu;
    return cache->J;
  };
  // Extended system: z = [x; p], lambda = mu.
  ArclengthSystem ext;
  ext.x_scale.resize(n + 1);
  ext.x_scale.head(n) = sys.x_scale;
  ext.x_scale[n] = sys.p_scale;
  ext.lambda_scale = sys.mu_scale;
  ext.r_scale.resize(n + 1);
  ext.r_scale.head(n) = R;
  ext.r_scale[n] = 1;
  ext.residual = [&](const Eigen::VectorXd& z, double mu) {
    const Eigen::VectorXd x = z.head(n);
    const Eigen::VectorXd r = F(x, z[n], mu);
    Eigen::VectorXd out(n + 1);
    out.head(n) = r;
    out[n] = calcFoldTest(sys, bord, jacobianAt(x, z[n], mu, r));
    return out;
  };
  ext.jacobian = [&](const Eigen::VectorXd& z, double mu, const Eigen::VectorXd& rz) {
    const Eigen::VectorXd x = z.head(n);
    const double p = z[n];
    const Eigen::VectorXd r = rz.head(n);
    const Eigen::MatrixXd J = jacobianAt(x, p, mu, r);
    Eigen::VectorXd v, w;
    calcFoldTest(sys, bord, J, &v, &w);
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n + 1, n + 2);
    G.topLeftCorner(n, n + 1) = J;
    const double hmu = 1.5e-8 * std::max(std::abs(mu), sys.mu_scale);
    G.block(0, n + 1, n, 1) = (F(x, p, mu + hmu) - r) / hmu;
    // dg/dz_j = -w' R (F(z + e Sv + h_j) - F(z + h_j) - F(z + e Sv) + F(z)) / (e h_j).
    const double e = options.difference_step;
    const Eigen::VectorXd dxv = e * sys.x_scale.cwiseProduct(v);
    const Eigen::VectorXd Fv = F(x + dxv, p, mu);
    const Eigen::VectorXd wR = w.cwiseProduct(R);
    auto column = [&](const Eigen::VectorXd& xj, double pj, double muj, double hj) {
      return -wR.dot(F(xj + dxv, pj, muj) - F(xj, pj, muj) - Fv + r) / (e * hj);
    };
    for (int j = 0; j < n; ++j) {
      Eigen::VectorXd xj = x;
      const double hj = options.difference_step * sys.x_scale[j];
      xj[j] += hj;
      G(n, j) = column(xj, p, mu, hj);
    }
    const double hp = options.difference_step * sys.p_scale, hm = options.difference_step * sys.mu_scale;
    G(n, n) = column(x, p + hp, mu, hp);
    G(n, n + 1) = column(x, p, mu + hm, hm);
    return G;
  };
  // g's noise floor is the finite-difference Jacobian's (~1e-8 of A's
  // scale): g is converged relative to the next singular value.
  const double gTol = options.g_tolerance * bord.second_singular_value;
  ext.converged = [&, gTol](const Eigen::VectorXd& rz) {
    return sys.converged(rz.head(n)) && std::abs(rz[n]) <= gTol;
  };
  if (sys.eigenvalues)
    ext.eigenvalues = [&](const Eigen::VectorXd& z, double mu) {
      return sys.eigenvalues(z.head(n), z[n], mu);
    };

  // Newton on the extended system at mu0 (square: [F_x F_p; g_x g_p]): the
  // one-parameter fold is located to its bracket, g = 0 to g_tolerance here.
  Eigen::VectorXd z(n + 1);
  z.head(n) = x0;
  z[n] = p0;
  Eigen::VectorXd rz = ext.residual(z, mu0);
  Eigen::VectorXd S = ext.x_scale;
  const int maxIt = std::max(options.continuation.max_corrector_iterations, 8);
  for (int it = 0; !ext.converged(rz); ++it) {
    if (it >= maxIt || !rz.allFinite())
      throw Error("fold curve: the start (p = " + formatValue(p0) + ", mu = " + formatValue(mu0) +
                  ") did not converge on F = 0, g = 0 in " + std::to_string(maxIt) +
                  " Newton iterations (|g| = " + formatValue(std::abs(rz[n])) + ", bound g_tolerance x second "
                  "singular value = " + formatValue(gTol) + "): not a simple fold");
    const Eigen::MatrixXd G = ext.jacobian(z, mu0, rz);
    const Eigen::MatrixXd Gs = ext.r_scale.asDiagonal() * G.leftCols(n + 1) * S.asDiagonal();
    const Eigen::VectorXd dz = S.cwiseProduct(Gs.fullPivLu().solve(-ext.r_scale.cwiseProduct(rz)));
    z += dz;
    rz = ext.residual(z, mu0);
  }
  res.continuation = continueArclength(ext, z, mu0, options.continuation);
  for (const auto& pt : res.continuation.points) {
    FoldCurvePoint fp;
    fp.x = pt.x.head(n);
    fp.p = pt.x[n];
    fp.mu = pt.lambda;
    fp.point = pt;
    fp.g = calcFoldTest(sys, bord, jacobianAt(fp.x, fp.p, fp.mu, F(fp.x, fp.p, fp.mu)));
    res.points.push_back(std::move(fp));
  }
  res.residual_evaluations = evaluations;
  return res;
}

}  // namespace vdyn
