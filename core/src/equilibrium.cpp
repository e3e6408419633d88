#include "vdyn/core/equilibrium.h"

#include "vdyn/core/euler_state.h"
#include "vdyn/core/log.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include <Eigen/Dense>

namespace vdyn {

StaticEquilibriumResult solveStaticEquilibrium(const Scene& scene, SimTK::State& state,
                                               const std::vector<SimTK::MobilizedBodyIndex>& ineffective,
                                               const StaticEquilibriumOptions& opt) {
  const SimTK::MultibodySystem& system = scene.getSystem();
  const SimTK::SimbodyMatterSubsystem& matter = scene.getMatter();
  system.realize(state, SimTK::Stage::Instance);
  // The same configuration with Euler angles, so nq == nu for every mobilizer.
  SimTK::State se = toEulerAngles(scene, state);
  system.realize(se, SimTK::Stage::Instance);
  se.updU() = 0;
  // With Euler angles there are no quaternion-normalization rows in qerr.
  if (se.getNUDotErr() != se.getNQErr())
    throw Error("static equilibrium: the scene has velocity or acceleration constraints; only position "
                "constraints are supported");

  std::vector<int> qs, us;  // unknown coordinates and the matching force equations
  for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b) {
    if (std::find(ineffective.begin(), ineffective.end(), b) != ineffective.end()) continue;
    const SimTK::MobilizedBody& mb = matter.getMobilizedBody(b);
    assert(mb.getNumQ(se) == mb.getNumU(se));
    for (int i = 0; i < mb.getNumQ(se); ++i) {
      qs.push_back(mb.getFirstQIndex(se) + i);
      us.push_back(mb.getFirstUIndex(se) + i);
    }
  }
  const int nq = static_cast<int>(qs.size()), mp = se.getNQErr(), n = nq + mp;
  if (nq == 0) throw Error("static equilibrium: every mobilizer is declared ineffective");

  const SimTK::Vector udot0(se.getNU(), 0.0);
  SimTK::Vector lambda(mp), residualForce, gtl;
  auto residual = [&](const Eigen::VectorXd& x) {
    for (int i = 0; i < nq; ++i) se.updQ()[qs[i]] = x[i];
    for (int i = 0; i < mp; ++i) lambda[i] = x[nq + i];
    system.realize(se, SimTK::Stage::Dynamics);
    matter.calcResidualForceIgnoringConstraints(se, system.getMobilityForces(se, SimTK::Stage::Dynamics),
                                                system.getRigidBodyForces(se, SimTK::Stage::Dynamics), udot0,
                                                residualForce);
    if (mp) {
      matter.multiplyByGTranspose(se, lambda, gtl);
      residualForce += gtl;
    }
    Eigen::VectorXd r(n);
    for (int i = 0; i < nq; ++i) r[i] = residualForce[us[i]];
    for (int i = 0; i < mp; ++i) r[nq + i] = se.getQErr()[i];
    return r;
  };
  auto merit = [&](const Eigen::VectorXd& r) {
    return std::hypot(r.head(nq).norm(), opt.constraint_weight * r.tail(mp).norm());
  };
  auto converged = [&](const Eigen::VectorXd& r) {
    return r.head(nq).lpNorm<Eigen::Infinity>() <= opt.force_tolerance &&
           (mp == 0 || r.tail(mp).lpNorm<Eigen::Infinity>() <= opt.constraint_tolerance);
  };

  Eigen::VectorXd x(n);
  for (int i = 0; i < nq; ++i) x[i] = se.getQ()[qs[i]];
  x.tail(mp).setZero();
  Eigen::VectorXd r = residual(x);
  StaticEquilibriumResult res;
  for (res.iterations = 0; !converged(r); ++res.iterations) {
    if (res.iterations == opt.max_iterations) break;
    Eigen::MatrixXd J(n, n);
    for (int j = 0; j < n; ++j) {
      const double typical = j < nq ? 1.0 : 1e3;  // rad or m for q; N for lambda
      const double h = 1.5e-8 * std::max(std::abs(x[j]), typical);
      Eigen::VectorXd xp = x;
      xp[j] += h;
      J.col(j) = (residual(xp) - r) / h;
    }
    const Eigen::VectorXd dx = J.fullPivLu().solve(-r);
    double alpha = 1.0;
    const double m0 = merit(r);
    Eigen::VectorXd xn, rn;
    bool decreased = false;
    for (int ls = 0; ls < 40 && !decreased; ++ls) {
      xn = x + alpha * dx;
      rn = residual(xn);
      decreased = rn.allFinite() && merit(rn) < m0;
      if (!decreased) alpha *= 0.5;
    }
    if (logEnabled(LogLevel::Debug))
      logMessage(LogLevel::Debug, logFormat("equilibrium: iteration %d alpha %g merit %g -> %g", res.iterations,
                                            alpha, m0, merit(rn)));
    if (!decreased) break;  // no descent: report below
    x = xn;
    r = rn;
  }
  r = residual(x);
  res.force_residual = r.head(nq).lpNorm<Eigen::Infinity>();
  res.constraint_error = mp ? r.tail(mp).lpNorm<Eigen::Infinity>() : 0.0;
  if (!converged(r)) {
    Eigen::Index worst;
    r.head(nq).cwiseAbs().maxCoeff(&worst);
    throw Error("static equilibrium did not converge: " + std::to_string(res.iterations) +
                " iterations, max force residual " + formatValue(res.force_residual) + " (tolerance " +
                formatValue(opt.force_tolerance) + ", worst in generalized speed u[" + std::to_string(us[worst]) +
                "]), max constraint error " + formatValue(res.constraint_error) + " (tolerance " +
                formatValue(opt.constraint_tolerance) + ")");
  }
  res.multipliers = lambda;
  res.force_residual_all = residualForce;
  const bool wasEuler = matter.getUseEulerAngles(state);
  SimTK::State out = wasEuler ? se : toQuaternions(scene, se);
  out.updU() = 0;
  state = out;
  system.realize(state, SimTK::Stage::Position);
  return res;
}

}  // namespace vdyn
