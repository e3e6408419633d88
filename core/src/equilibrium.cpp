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

  auto jacobian = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& r) {
    Eigen::MatrixXd J(n, n);
    for (int j = 0; j < n; ++j) {
      const double typical = j < nq ? 1.0 : 1e3;  // rad or m for q; N for lambda
      const double h = 1.5e-8 * std::max(std::abs(x[j]), typical);
      Eigen::VectorXd xp = x;
      xp[j] += h;
      J.col(j) = (residual(xp) - r) / h;
    }
    return J;
  };
  auto worstEquation = [&](const Eigen::VectorXd& r) {
    Eigen::Index worst;
    r.head(nq).cwiseAbs().maxCoeff(&worst);
    return us[worst];
  };
  auto logIteration = [&](bool newton, int it, double step, double m0, double m1, const Eigen::VectorXd& x,
                          const Eigen::VectorXd& r, const Eigen::MatrixXd& J) {
    if (!logEnabled(LogLevel::Debug)) return;
    const Eigen::VectorXd sv = J.jacobiSvd().singularValues();
    std::string xs;
    for (int i = 0; i < nq; ++i) xs += logFormat(" %.6g", x[i]);
    logMessage(LogLevel::Debug,
               logFormat("equilibrium: %siteration %d %s %g merit %g -> %g, max force %g at u[%d], max qerr %g, "
                         "Jacobian singular values max %g min %g, q:%s",
                         newton ? "" : "Levenberg-Marquardt ", it, newton ? "alpha" : "damping", step, m0, m1, r.head(nq).lpNorm<Eigen::Infinity>(), worstEquation(r),
                         mp ? r.tail(mp).lpNorm<Eigen::Infinity>() : 0.0, sv[0], sv[n - 1], xs.c_str()));
  };

  Eigen::VectorXd x(n);
  for (int i = 0; i < nq; ++i) x[i] = se.getQ()[qs[i]];
  x.tail(mp).setZero();
  Eigen::VectorXd r = residual(x);
  StaticEquilibriumResult res;
  // 1. Newton-Raphson with a backtracking line search: the first try, and the
  // whole solve wherever it converges (its results are kept bit for bit).
  for (res.newton_iterations = 0; !converged(r); ++res.newton_iterations) {
    if (res.newton_iterations == opt.max_iterations) break;
    const Eigen::MatrixXd J = jacobian(x, r);
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
    logIteration(true, res.newton_iterations, alpha, m0, merit(rn), x, r, J);
    if (!decreased) break;  // no descent: the fallback below, or the report
    x = xn;
    r = rn;
  }
  // 2. Fallback: Levenberg-Marquardt on the weighted residual w = (force rows,
  // constraint_weight * constraint rows), whose half square is the line search's
  // merit. Chosen over a pseudo-transient (damped dynamics) because it needs no
  // mass matrix or time step, works on the same residual and Jacobian, and
  // where Newton fails at a fold (a stationary point of the merit with a
  // singular Jacobian, as the quarter car with App. A's 0.344 m spring, which
  // has no rest pose in bump) it stops at that minimum and can say so, while a
  // damped transient of a model without a rest pose runs away through the
  // linkage's toggle. Near a root the damping falls geometrically and the
  // steps become Newton steps, which polish the solution to the tolerances.
  bool stationary = false;
  double sigmaMin = 0;
  if (!converged(r) && r.allFinite()) {
    Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
    w.tail(mp).setConstant(opt.constraint_weight);
    double mu = -1;
    for (res.trust_region_iterations = 0; !converged(r); ++res.trust_region_iterations) {
      if (res.trust_region_iterations == opt.trust_region_iterations) break;
      const Eigen::MatrixXd J = jacobian(x, r);
      const Eigen::MatrixXd Jw = w.asDiagonal() * J;
      const Eigen::VectorXd rw = w.cwiseProduct(r);
      const Eigen::MatrixXd A = Jw.transpose() * Jw;
      const Eigen::VectorXd g = Jw.transpose() * rw;
      const Eigen::VectorXd d = A.diagonal().cwiseMax(1e-300);  // Marquardt's scaling
      if (mu < 0) mu = opt.trust_region_initial_damping;
      // A stationary point of the merit that is not a root: no equilibrium near here.
      if (g.norm() <= opt.stationary_tolerance * Jw.norm() * rw.norm()) {
        stationary = true;
        break;
      }
      const double m0 = merit(r);
      bool decreased = false;
      Eigen::VectorXd xn, rn;
      while (!decreased && mu < 1e20) {
        Eigen::MatrixXd Am = A;
        Am.diagonal() += mu * d;
        xn = x + Am.ldlt().solve(-g);
        rn = residual(xn);
        decreased = rn.allFinite() && merit(rn) < m0;
        mu = decreased ? std::max(mu / 3, 1e-15) : mu * 4;
      }
      logIteration(false, res.trust_region_iterations, mu, m0, decreased ? merit(rn) : m0, x, r, J);
      if (!decreased) {  // no step reduces the merit: a minimum to round-off
        stationary = true;
        break;
      }
      x = xn;
      r = rn;
    }
    if (!converged(r)) sigmaMin = jacobian(x, r).jacobiSvd().singularValues()[n - 1];
  }
  res.iterations = res.newton_iterations + res.trust_region_iterations;
  r = residual(x);
  res.force_residual = r.head(nq).lpNorm<Eigen::Infinity>();
  res.constraint_error = mp ? r.tail(mp).lpNorm<Eigen::Infinity>() : 0.0;
  if (!converged(r)) {
    std::string pose;
    for (int i = 0; i < nq; ++i) pose += (i ? ", q[" : "q[") + std::to_string(qs[i]) + "] " + formatValue(x[i]);
    throw Error("static equilibrium did not converge: " + std::to_string(res.newton_iterations) +
                " Newton and " + std::to_string(res.trust_region_iterations) +
                " Levenberg-Marquardt iterations, max force residual " + formatValue(res.force_residual) +
                " (tolerance " + formatValue(opt.force_tolerance) + ", worst in generalized speed u[" +
                std::to_string(worstEquation(r)) + "]), max constraint error " + formatValue(res.constraint_error) +
                " (tolerance " + formatValue(opt.constraint_tolerance) + ")" +
                (stationary ? "; the residual has a local minimum here (smallest singular value of the Jacobian " +
                                  formatValue(sigmaMin) +
                                  "): no static equilibrium near this start (past a fold the model may have no "
                                  "rest pose)"
                            : "") +
                " at " + pose + " (Euler angles)");
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
