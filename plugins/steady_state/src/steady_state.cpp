#include "vdyn/steady_state/steady_state.h"

#include "vdyn/core/euler_state.h"
#include "vdyn/core/log.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vdyn {

using SimTK::Vec3;

namespace {
double maxAbs(const Eigen::VectorXd& v) { return v.size() ? v.lpNorm<Eigen::Infinity>() : 0.0; }
bool contains(const std::vector<int>& v, int i) { return std::find(v.begin(), v.end(), i) != v.end(); }
}  // namespace

SteadyStateProblem makeSteadyTurningProblem(const Scene& scene, const std::string& chassisBody,
                                            const std::vector<std::string>& wheelBodies, double time_s) {
  const SimTK::MobilizedBody& chassis = scene.getBody(chassisBody);
  const SimTK::State se = toEulerAngles(scene, scene.getDefaultState());
  if (chassis.getNumQ(se) != 6 || chassis.getNumU(se) != 6)
    throw Error("steady turning: chassis '" + chassisBody + "' must be on a free mobilizer (6 q and 6 u), has " +
                std::to_string(chassis.getNumU(se)) + " u");
  SteadyStateProblem p;
  p.time_s = requireFinite(time_s, "steady turning time_s");
  const int q0 = chassis.getFirstQIndex(se), u0 = chassis.getFirstUIndex(se);
  // Free mobilizer, Euler form: q = [body-XYZ angles, position], u = [w_G, v_G].
  p.ineffective_q = {q0 + 2, q0 + 3, q0 + 4};  // third XYZ angle (yaw), x, y
  p.effective_u = {u0 + 2, u0 + 3, u0 + 4};    // yaw rate, horizontal velocity
  for (const auto& name : wheelBodies) {
    const SimTK::MobilizedBody& w = scene.getBody(name);
    if (w.getNumQ(se) != 1 || w.getNumU(se) != 1)
      throw Error("steady turning: wheel '" + name + "' must be on a one-coordinate (spin) mobilizer");
    p.ineffective_q.push_back(w.getFirstQIndex(se));
    p.cyclic_q.push_back(w.getFirstQIndex(se));
    p.effective_u.push_back(w.getFirstUIndex(se));
  }
  p.floating_base = chassis.getMobilizedBodyIndex();
  // (3.19): a steady turn at yaw rate w moves the chassis origin on a circle,
  // its velocity turning with it: a = w x v; every other acceleration is zero.
  p.calc_steady_udot = [u0](const SimTK::State& s, SimTK::Vector& udot) {
    const SimTK::Vector& u = s.getU();
    const Vec3 w(u[u0], u[u0 + 1], u[u0 + 2]), v(u[u0 + 3], u[u0 + 4], u[u0 + 5]);
    const Vec3 a = SimTK::cross(w, v);
    for (int i = 0; i < 3; ++i) udot[u0 + 3 + i] = a[i];
  };
  return p;
}

SteadyStateProblem makeRestProblem(const Scene& scene, const std::string& chassisBody,
                                   const std::vector<std::string>& wheelBodies, double time_s) {
  SteadyStateProblem p = makeSteadyTurningProblem(scene, chassisBody, wheelBodies, time_s);
  p.checked_u = std::move(p.effective_u);  // yaw rate, horizontal velocity, spins: held at zero
  p.effective_u.clear();
  p.calc_steady_udot = nullptr;  // at rest every acceleration is zero
  return p;
}

// ---------------------------------------------------------------------------
SteadyStateSolver::SteadyStateSolver(const Scene& scene, SteadyStateProblem problem, SteadyStateOptions options)
    : scene_(scene), problem_(std::move(problem)), opt_(options) {
  se_ = toEulerAngles(scene_, scene_.getDefaultState());
  // In Euler-angle form every mobilizer has as many q as u; Simbody keeps the
  // q vector at its quaternion size, so the coordinates in use are listed.
  const SimTK::SimbodyMatterSubsystem& matter = scene_.getMatter();
  for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b) {
    const SimTK::MobilizedBody& mb = matter.getMobilizedBody(b);
    if (mb.getNumQ(se_) != mb.getNumU(se_))
      throw Error("steady state: mobilizer of body " + std::to_string(int(b)) + " has nq != nu in Euler-angle form");
    for (int i = 0; i < mb.getNumQ(se_); ++i) qAll_.push_back(mb.getFirstQIndex(se_) + i);
  }
  nq_ = int(qAll_.size());
  nu_ = se_.getNU();
  nz_ = se_.getNZ();
  if (nq_ != nu_)
    throw Error("steady state: the Euler-angle state has nq (" + std::to_string(nq_) + ") != nu (" + std::to_string(nu_) + ")");
  mp_ = se_.getNQErr();
  mv_ = se_.getNUErr() - mp_;
  m_ = se_.getNMultipliers();
  if (se_.getNUDotErr() != mp_ + mv_)
    throw Error("steady state: acceleration-only constraints are not supported (" +
                std::to_string(se_.getNUDotErr() - mp_ - mv_) + " found)");
  for (int i : problem_.ineffective_q)
    if (!contains(qAll_, i)) throw Error("steady state: ineffective q index " + std::to_string(i) + " is not a coordinate in use");
  for (int i : problem_.effective_u)
    if (i < 0 || i >= nu_) throw Error("steady state: effective u index " + std::to_string(i) + " out of range");
  for (int i : qAll_)
    if (!contains(problem_.ineffective_q, i)) qe_.push_back(i);
  ue_ = problem_.effective_u;
  std::sort(ue_.begin(), ue_.end());
  ue_.erase(std::unique(ue_.begin(), ue_.end()), ue_.end());
  cu_ = problem_.checked_u;
  std::sort(cu_.begin(), cu_.end());
  cu_.erase(std::unique(cu_.begin(), cu_.end()), cu_.end());
  for (int i : cu_) {
    if (i < 0 || i >= nu_) throw Error("steady state: checked u index " + std::to_string(i) + " out of range");
    if (contains(ue_, i))
      throw Error("steady state: u index " + std::to_string(i) + " is both effective (solved) and checked (held at 0)");
  }
  for (int i = 0; i < nu_; ++i)
    if (!contains(cu_, i)) fu_.push_back(i);
  nf_ = int(fu_.size());
  if (int(qe_.size() + ue_.size()) != nf_)
    throw Error("steady state: effective coordinates (" + std::to_string(qe_.size()) + ") plus effective speeds (" +
                std::to_string(ue_.size()) + ") must equal the number of mobilities (" + std::to_string(nu_) +
                ") less the checked ones (" + std::to_string(cu_.size()) + ") so that unknowns and equations match");
  np_ = int(problem_.parameters.size());
  if (int(problem_.conditions.size()) != np_)
    throw Error("steady state: " + std::to_string(np_) + " extra unknowns (parameters) but " +
                std::to_string(problem_.conditions.size()) + " extra conditions; they must match");
  for (const auto& p : problem_.parameters)
    if (!p.get || !p.set || !(p.typical > 0))
      throw Error("steady state: parameter '" + p.name + "' needs get, set and a positive typical size");
  for (const auto& c : problem_.conditions)
    if (!c.calc || !(c.tolerance > 0) || !(c.weight > 0))
      throw Error("steady state: condition '" + c.name + "' needs calc, a positive tolerance and weight");
  n_ = nf_ + m_ + nz_ + np_;
  for (const auto& p : problem_.parameters) curP_.push_back(p.get(se_));
  // Typical sizes of the unknowns (finite-difference steps) and weights that
  // bring every equation to newtons (merit and convergence report).
  xScale_.resize(n_);
  int k = 0;
  for (std::size_t i = 0; i < qe_.size(); ++i) xScale_[k++] = 0.1;  // m or rad
  for (std::size_t i = 0; i < ue_.size(); ++i) xScale_[k++] = 1.0;  // m/s or rad/s
  for (int i = 0; i < m_; ++i) xScale_[k++] = 1e3;                    // N
  for (int i = 0; i < nz_; ++i) xScale_[k++] = 1e-3;                  // tire lag states, m
  for (const auto& p : problem_.parameters) xScale_[k++] = p.typical;
  rScale_.resize(n_);
  rScale_.head(nf_).setConstant(1.0);
  rScale_.segment(nf_, mp_).setConstant(1e6);     // N per m of constraint error
  rScale_.segment(nf_ + mp_, mv_).setConstant(1e4);  // N per m/s
  rScale_.segment(nf_ + m_, nz_).setConstant(1e5);  // N per m/s of patch-deflection rate
  for (int i = 0; i < np_; ++i) rScale_[nf_ + m_ + nz_ + i] = problem_.conditions[i].weight;
}

Eigen::VectorXd SteadyStateSolver::getUnknowns(const SimTK::State& se, const SimTK::Vector& lambda) const {
  Eigen::VectorXd x(n_);
  int k = 0;
  for (int i : qe_) x[k++] = se.getQ()[i];
  for (int i : ue_) x[k++] = se.getU()[i];
  for (int i = 0; i < m_; ++i) x[k++] = i < lambda.size() ? lambda[i] : 0.0;
  for (int i = 0; i < nz_; ++i) x[k++] = se.getZ()[i];
  for (const auto& p : problem_.parameters) x[k++] = p.get(se);
  return x;
}

Eigen::VectorXd SteadyStateSolver::getUnknowns(const SteadyStateResult& r) const {
  Eigen::VectorXd x = getUnknowns(r.euler_state, r.multipliers);
  for (int i = 0; i < np_ && i < int(r.parameters.size()); ++i) x[nf_ + m_ + nz_ + i] = r.parameters[i];
  return x;
}

void SteadyStateSolver::setGuess(const Eigen::VectorXd& x, SteadyStateResult& guess) const {
  assert(x.size() == n_);
  SimTK::State& g = guess.euler_state;
  int k = 0;
  for (int i : qe_) g.updQ()[i] = x[k++];
  for (int i : ue_) g.updU()[i] = x[k++];
  guess.multipliers.resize(m_);
  for (int i = 0; i < m_; ++i) guess.multipliers[i] = x[k++];
  for (int i = 0; i < nz_; ++i) g.updZ()[i] = x[k++];
  guess.parameters.resize(np_);
  for (int i = 0; i < np_; ++i) guess.parameters[i] = x[k++];
}

void SteadyStateSolver::setUnknowns(const Eigen::VectorXd& x) const {
  // Touch only what changed, so Simbody keeps the stages that are still valid.
  int k = 0;
  bool qChanged = false, uChanged = false, zChanged = false;
  for (int i : qe_) qChanged |= se_.getQ()[i] != x[k++];
  for (int i : ue_) uChanged |= se_.getU()[i] != x[k++];
  k += m_;
  for (int i = 0; i < nz_; ++i) zChanged |= se_.getZ()[i] != x[k++];
  k = 0;
  if (qChanged) {
    SimTK::Vector& q = se_.updQ();
    for (int i : qe_) q[i] = x[k++];
  } else {
    k += int(qe_.size());
  }
  if (uChanged) {
    SimTK::Vector& u = se_.updU();
    for (int i : ue_) u[i] = x[k++];
  } else {
    k += int(ue_.size());
  }
  k += m_;
  if (zChanged) {
    SimTK::Vector& z = se_.updZ();
    for (int i = 0; i < nz_; ++i) z[i] = x[k++];
  } else {
    k += nz_;
  }
  bool pChanged = false;
  for (int i = 0; i < np_; ++i) {
    const double v = x[k++];
    if (v != curP_[i]) {
      problem_.parameters[i].set(se_, v);
      curP_[i] = v;
      pChanged = true;
    }
  }
  if (pChanged) se_.invalidateAll(SimTK::Stage::Position);  // the model changed
}

Eigen::VectorXd SteadyStateSolver::calcEquations(const Eigen::VectorXd& x) const {
  ++evaluations_;
  setUnknowns(x);
  const SimTK::MultibodySystem& system = scene_.getSystem();
  const SimTK::SimbodyMatterSubsystem& matter = scene_.getMatter();
  system.realize(se_, SimTK::Stage::Dynamics);
  SimTK::Vector udot(nu_, 0.0), residual, gtl;
  if (problem_.calc_steady_udot) problem_.calc_steady_udot(se_, udot);
  matter.calcResidualForceIgnoringConstraints(se_, system.getMobilityForces(se_, SimTK::Stage::Dynamics),
                                              system.getRigidBodyForces(se_, SimTK::Stage::Dynamics), udot,
                                              residual);
  if (m_) {
    SimTK::Vector lambda(m_);
    for (int i = 0; i < m_; ++i) lambda[i] = x[nf_ + i];
    matter.multiplyByGTranspose(se_, lambda, gtl);
    residual += gtl;  // M udot - f + G^T lambda (Simbody's sign)
  }
  Eigen::VectorXd r(n_);
  for (int i = 0; i < nf_; ++i) r[i] = residual[fu_[i]];
  checkedForces_.resize(int(cu_.size()));
  for (std::size_t i = 0; i < cu_.size(); ++i) checkedForces_[i] = residual[cu_[i]];
  for (int i = 0; i < mp_; ++i) r[nf_ + i] = se_.getQErr()[i];
  for (int i = 0; i < mv_; ++i) r[nf_ + mp_ + i] = se_.getUErr()[mp_ + i];
  for (int i = 0; i < nz_; ++i) r[nf_ + m_ + i] = se_.getZDot()[i];
  for (int i = 0; i < np_; ++i) r[nf_ + m_ + nz_ + i] = problem_.conditions[i].calc(se_);
  return r;
}

void SteadyStateSolver::calcJacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& r, Eigen::MatrixXd& J) const {
  J.resize(n_, n_);
  // Multiplier columns are exact: d r / d lambda = [G^T; 0].
  setUnknowns(x);  // G depends on q (and, for velocity constraints, on u)
  scene_.getSystem().realize(se_, SimTK::Stage::Velocity);
  SimTK::Vector e(m_, 0.0), col;
  for (int j = 0; j < m_; ++j) {
    e[j] = 1.0;
    scene_.getMatter().multiplyByGTranspose(se_, e, col);
    e[j] = 0.0;
    J.col(nf_ + j).setZero();
    for (int i = 0; i < nf_; ++i) J(i, nf_ + j) = col[fu_[i]];
  }
  // The others by forward differences (3.16): step sqrt(eps) of the typical size.
  for (int j = 0; j < n_; ++j) {
    if (j >= nf_ && j < nf_ + m_) continue;
    const double h = 1.5e-8 * std::max(std::abs(x[j]), xScale_[j]);
    Eigen::VectorXd xp = x;
    xp[j] += h;
    J.col(j) = (calcEquations(xp) - r) / h;
  }
  setUnknowns(x);
}

std::string SteadyStateSolver::describeEquation(int row) const {
  if (row < 0) row = cu_[-1 - row];  // checked equation -1 - k
  else if (row < nf_) row = fu_[row];
  else row += nu_ - nf_;
  if (row < nu_) {
    const SimTK::SimbodyMatterSubsystem& matter = scene_.getMatter();
    for (SimTK::MobilizedBodyIndex b(0); b < matter.getNumBodies(); ++b) {
      const SimTK::MobilizedBody& mb = matter.getMobilizedBody(b);
      const int u0 = mb.getFirstUIndex(se_);
      if (row >= u0 && row < u0 + mb.getNumU(se_))
        return "generalized force u[" + std::to_string(row) + "] (mobilizer of body " + std::to_string(int(b)) +
               ", its u " + std::to_string(row - u0) + ")";
    }
    return "generalized force u[" + std::to_string(row) + "]";
  }
  if (row < nu_ + mp_) return "position constraint error " + std::to_string(row - nu_);
  if (row < nu_ + m_) return "velocity constraint error " + std::to_string(row - nu_ - mp_);
  if (row < nu_ + m_ + nz_) return "auxiliary state rate zdot[" + std::to_string(row - nu_ - m_) + "]";
  return "condition '" + problem_.conditions[row - nu_ - m_ - nz_].name + "'";
}

SteadyStateResult SteadyStateSolver::solve(const SimTK::State& guess) {
  SimTK::State g = guess;  // the steady equations take Simbody's rows (their multipliers are unknowns)
  if (scene_.hasService(kConstraintRowsService))
    scene_.getService<const ConstraintRowsService>(kConstraintRowsService)->use_simbody_rows(g);
  const SimTK::State se = toEulerAngles(scene_, g);
  haveJacobian_ = false;
  std::vector<double> p0;
  for (const auto& p : problem_.parameters) p0.push_back(p.get(guess));
  return solveFrom(se, SimTK::Vector(m_, 0.0), p0);
}

SteadyStateResult SteadyStateSolver::resolve(const SteadyStateResult& previous) {
  std::vector<double> p0 = previous.parameters;
  if (int(p0.size()) != np_) {
    p0.clear();
    for (const auto& p : problem_.parameters) p0.push_back(p.get(previous.euler_state));
  }
  return solveFrom(previous.euler_state, previous.multipliers, p0);
}

SteadyStateResult SteadyStateSolver::solveFrom(SimTK::State se, const SimTK::Vector& lambda0,
                                               const std::vector<double>& p0) {
  const auto t0 = std::chrono::steady_clock::now();
  const SimTK::MultibodySystem& system = scene_.getSystem();
  se.setTime(problem_.time_s);
  // Zero variables are zero; the remaining state is the start.
  {
    SimTK::Vector u(nu_, 0.0);
    for (int i : ue_) u[i] = se.getU()[i];
    se.updU() = u;
  }
  system.realize(se, SimTK::Stage::Instance);
  if (se.getNQ() != se_.getNQ() || se.getNU() != nu_ || se.getNZ() != nz_)
    throw Error("steady state: the start state does not belong to the solver's scene");
  se_ = se;
  drivenLambda_ = std::numeric_limits<double>::quiet_NaN();  // the workspace holds the start's own model
  curP_ = p0;
  for (int i = 0; i < np_; ++i) problem_.parameters[i].set(se_, p0[i]);
  se_.invalidateAll(SimTK::Stage::Position);  // commands may have changed (model parameters)
  evaluations_ = 0;

  SteadyStateResult res;
  Eigen::VectorXd x = getUnknowns(se_, lambda0);
  for (int i = 0; i < np_; ++i) x[nf_ + m_ + nz_ + i] = p0[i];
  Eigen::VectorXd r = calcEquations(x);
  auto merit = [&](const Eigen::VectorXd& rr) { return rr.cwiseProduct(rScale_).norm(); };
  auto blocks = [&](const Eigen::VectorXd& rr, double& f, double& p, double& v, double& z) {
    f = maxAbs(rr.head(nf_));
    p = maxAbs(rr.segment(nf_, mp_));
    v = maxAbs(rr.segment(nf_ + mp_, mv_));
    z = maxAbs(rr.segment(nf_ + m_, nz_));
  };
  auto conditionsMet = [&](const Eigen::VectorXd& rr) {
    for (int i = 0; i < np_; ++i)
      if (!(std::abs(rr[nf_ + m_ + nz_ + i]) <= problem_.conditions[i].tolerance)) return false;
    return true;
  };
  auto converged = [&](const Eigen::VectorXd& rr) {
    double f, p, v, z;
    blocks(rr, f, p, v, z);
    return f <= opt_.force_tolerance && p <= opt_.position_tolerance && v <= opt_.velocity_tolerance &&
           z <= opt_.rate_tolerance && conditionsMet(rr);
  };
  bool fresh = false;  // J_ was computed at the current x
  // A start that already solves the equations needs no Jacobian.
  bool needJacobian = !haveJacobian_ || !opt_.broyden || opt_.fresh_jacobian_each_solve;
  bool stalled = false;
  for (res.iterations = 0; !converged(r); ++res.iterations) {
    if (res.iterations == opt_.max_iterations) break;
    if (needJacobian) {
      calcJacobian(x, r, J_);
      ++res.jacobians;
      haveJacobian_ = fresh = true;
      needJacobian = false;
    }
    // Equilibrated solve: rows to newtons, columns to typical sizes.
    const Eigen::MatrixXd Js = rScale_.asDiagonal() * J_ * xScale_.asDiagonal();
    Eigen::VectorXd dx = xScale_.cwiseProduct(Js.partialPivLu().solve(-r.cwiseProduct(rScale_)));
    if (!dx.allFinite()) dx.setZero();
    const double m0 = merit(r);
    double alpha = 1.0;
    Eigen::VectorXd xn, rn;
    bool decreased = false;
    for (int ls = 0; ls < 30 && !decreased && dx.squaredNorm() > 0; ++ls) {
      xn = x + alpha * dx;
      rn = calcEquations(xn);
      decreased = rn.allFinite() && merit(rn) < (1.0 - 1e-4 * alpha) * m0;
      if (!decreased) alpha *= 0.5;
    }
    // A step of a fresh Jacobian that descends only a little (merit above
    // half the start's: the linear model overshoots, e.g. saturating tires
    // far from the solution) is compared with shorter ones, halving while
    // the merit falls. The sufficient-decrease test alone accepted a full
    // step that gained 1 % where half of it gained 75 %, and which of two
    // nearly equal merits passed it decided the branch Newton ended on: the
    // reduced and the constrained forms of App. A (start merits 2 % apart)
    // went from the same straight start to different steady 4/1 deg turns
    // at 10 m/s (yaw rate -0.716 against 0.242 rad/s).
    if (fresh && decreased) {
      double mn = merit(rn);
      for (int ls = 0; ls < 10 && mn > 0.5 * m0; ++ls) {
        const Eigen::VectorXd xh = x + 0.5 * alpha * dx;
        const Eigen::VectorXd rh = calcEquations(xh);
        if (!rh.allFinite() || !(merit(rh) < mn)) break;
        alpha *= 0.5;
        xn = xh;
        rn = rh;
        mn = merit(rh);
      }
    }
    if (logEnabled(LogLevel::Debug))
      logMessage(LogLevel::Debug, logFormat("steady: it %d alpha %g merit %.3e -> %.3e%s", res.iterations, alpha, m0,
                                            decreased ? merit(rn) : m0, fresh ? " (fresh J)" : ""));
    if (!decreased) {
      if (fresh) {
        stalled = true;
        break;
      }
      calcJacobian(x, r, J_);  // the updated Jacobian misled the step: take a fresh one
      ++res.jacobians;
      fresh = true;
      continue;
    }
    if (opt_.broyden) {
      // Good Broyden update: J += (dr - J dx) dx^T / (dx^T dx), in scaled unknowns.
      const Eigen::VectorXd s = xn - x, y = rn - r;
      const Eigen::VectorXd ss = s.cwiseQuotient(xScale_);
      J_ += ((y - J_ * s) * ss.cwiseQuotient(xScale_).transpose()) / ss.squaredNorm();
      fresh = false;
      // A slow step (merit reduced by less than half) asks for a fresh Jacobian next time.
      if (merit(rn) > 0.5 * m0) {
        calcJacobian(xn, rn, J_);
        ++res.jacobians;
        fresh = true;
      }
    } else {
      x = xn;
      r = rn;
      calcJacobian(x, r, J_);
      ++res.jacobians;
      continue;
    }
    x = xn;
    r = rn;
  }
  // r is the residual at x; a rejected line-search trial may have moved the workspace.
  setUnknowns(x);
  blocks(r, res.force_residual, res.position_error, res.velocity_error, res.rate_residual);
  res.residual_norm = merit(r);
  res.condition_residual = maxAbs(r.tail(np_));
  res.residual_evaluations = evaluations_;
  if (!converged(r)) {
    haveJacobian_ = false;
    Eigen::Index worst;
    r.cwiseProduct(rScale_).cwiseAbs().maxCoeff(&worst);
    // Each block against its own tolerance, so the message says which one failed
    // (a force residual below its tolerance is never reported as the cause).
    std::string failing, blocksText;
    auto block = [&](const char* what, double v, double tol, const char* unit) {
      const bool met = v <= tol;
      blocksText += std::string(blocksText.empty() ? "" : ", ") + what + " " + formatValue(v) + unit + " (tolerance " +
                    formatValue(tol) + (met ? ")" : ", NOT met)");
      if (!met) failing += std::string(failing.empty() ? "" : " and ") + what;
    };
    block("max force residual", res.force_residual, opt_.force_tolerance, " N");
    block("max position-constraint error", res.position_error, opt_.position_tolerance, "");
    block("max velocity-constraint error", res.velocity_error, opt_.velocity_tolerance, "");
    block("max zdot", res.rate_residual, opt_.rate_tolerance, "");
    // The extra conditions are part of convergence too (conditionsMet): each named.
    for (int i = 0; i < np_; ++i)
      block(("condition '" + problem_.conditions[i].name + "'").c_str(), std::abs(r[nf_ + m_ + nz_ + i]),
            problem_.conditions[i].tolerance, "");
    throw SteadyStateError(
        std::string("steady state did not converge") + (stalled ? " (no descent along the Newton direction)" : "") +
        ": " + std::to_string(res.iterations) + " iterations; failing: " + failing + "; " + blocksText +
        "; worst equation (scaled): " + describeEquation(int(worst)) + " = " + formatValue(r[worst]) +
        " (no steady state may exist here: beyond the limit of adhesion or past a fold of the branch)");
  }
  if (!cu_.empty()) {
    // The checked equations have no unknown: at the solution they vanish on
    // their own (a vehicle at rest on a flat road: no tire in-plane force at
    // zero slip) or the problem has no solution with those speeds held at 0.
    r = calcEquations(x);  // sets checkedForces_ at x (evaluations are pure: r is unchanged)
    res.residual_evaluations = evaluations_;
    Eigen::Index worst = 0;
    const double f = checkedForces_.cwiseAbs().maxCoeff(&worst);
    if (!(f <= opt_.force_tolerance))
      throw SteadyStateError("steady state: the solved equations converged in " + std::to_string(res.iterations) +
                             " iterations, but " + describeEquation(-1 - int(worst)) + " = " +
                             formatValue(checkedForces_[worst]) + " N (tolerance " + formatValue(opt_.force_tolerance) +
                             " N): that mobility's speed is held at zero and its equation is checked, not solved "
                             "(SteadyStateProblem::checked_u); a vehicle at rest needs no tire in-plane force at zero "
                             "slip (a tire with camber thrust, conicity or ply steer at rest creeps)");
  }
  fillResult(x, r, res);
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

bool SteadyStateSolver::meetsTolerances(const Eigen::VectorXd& r) const {
  if (maxAbs(r.head(nf_)) > opt_.force_tolerance || maxAbs(r.segment(nf_, mp_)) > opt_.position_tolerance ||
      maxAbs(r.segment(nf_ + mp_, mv_)) > opt_.velocity_tolerance || maxAbs(r.segment(nf_ + m_, nz_)) > opt_.rate_tolerance)
    return false;
  for (int i = 0; i < np_; ++i)
    if (!(std::abs(r[nf_ + m_ + nz_ + i]) <= problem_.conditions[i].tolerance)) return false;
  return r.allFinite();
}

void SteadyStateSolver::fillResult(const Eigen::VectorXd& x, const Eigen::VectorXd& r, SteadyStateResult& res) const {
  res.force_residual = std::max(maxAbs(r.head(nf_)), maxAbs(checkedForces_));
  res.position_error = maxAbs(r.segment(nf_, mp_));
  res.velocity_error = maxAbs(r.segment(nf_ + mp_, mv_));
  res.rate_residual = maxAbs(r.segment(nf_ + m_, nz_));
  res.residual_norm = r.cwiseProduct(rScale_).norm();
  res.condition_residual = maxAbs(r.tail(np_));
  res.multipliers.resize(m_);
  for (int i = 0; i < m_; ++i) res.multipliers[i] = x[nf_ + i];
  res.parameters.assign(x.data() + nf_ + m_ + nz_, x.data() + n_);
  res.euler_state = se_;
  res.state = toQuaternions(scene_, se_);
  scene_.getSystem().realize(res.state, SimTK::Stage::Velocity);
}

// --- pseudo-arclength continuation's pieces -------------------------------------
void SteadyStateSolver::beginDriven(const SteadyStateResult& start, std::function<void(SimTK::State&, double)> drive,
                                    double lambda_scale) {
  if (!drive) throw Error("steady state continuation: no driving condition");
  if (!cu_.empty())
    throw Error("steady state continuation: the problem has checked equations (SteadyStateProblem::checked_u, a "
                "static equilibrium at rest); continuation solves steady motions only");
  requirePositive(lambda_scale, "steady state continuation: typical size of the driving condition");
  SimTK::State se = start.euler_state;
  se.setTime(problem_.time_s);
  scene_.getSystem().realize(se, SimTK::Stage::Instance);
  se_ = se;
  curP_ = start.parameters.size() == std::size_t(np_) ? start.parameters : curP_;
  for (int i = 0; i < np_; ++i) problem_.parameters[i].set(se_, curP_[i]);
  se_.invalidateAll(SimTK::Stage::Position);
  drive_ = std::move(drive);
  driveScale_ = lambda_scale;
  drivenLambda_ = std::numeric_limits<double>::quiet_NaN();
  haveJacobian_ = false;  // the next solve() takes a fresh Jacobian
}

void SteadyStateSolver::applyDrive(double lambda) const {
  if (!drive_) throw Error("steady state continuation: beginDriven was not called");
  if (lambda == drivenLambda_) return;
  drive_(se_, lambda);
  se_.invalidateAll(SimTK::Stage::Position);  // the model changed
  drivenLambda_ = lambda;
}

Eigen::VectorXd SteadyStateSolver::calcDrivenEquations(const Eigen::VectorXd& x, double lambda) const {
  applyDrive(lambda);
  return calcEquations(x);
}

Eigen::MatrixXd SteadyStateSolver::calcDrivenJacobian(const Eigen::VectorXd& x, double lambda,
                                                      const Eigen::VectorXd& r) const {
  applyDrive(lambda);
  Eigen::MatrixXd Jx;
  calcJacobian(x, r, Jx);
  Eigen::MatrixXd J(n_, n_ + 1);
  J.leftCols(n_) = Jx;
  const double h = 1.5e-8 * std::max(std::abs(lambda), driveScale_);
  applyDrive(lambda + h);
  J.col(n_) = (calcEquations(x) - r) / h;
  applyDrive(lambda);
  setUnknowns(x);
  return J;
}

SimTK::State SteadyStateSolver::getDrivenEulerState(const Eigen::VectorXd& x, double lambda) const {
  applyDrive(lambda);
  setUnknowns(x);
  return se_;
}

SteadyStateResult SteadyStateSolver::makeDrivenResult(const Eigen::VectorXd& x, double lambda) const {
  applyDrive(lambda);
  const Eigen::VectorXd r = calcEquations(x);
  SteadyStateResult res;
  fillResult(x, r, res);
  return res;
}

// --- stability -----------------------------------------------------------------
namespace {
/// Reduced coordinates of a state modulo the base's yaw and horizontal
/// position: base height, ZYX roll and pitch, base velocities in the yawed frame,
/// every other q (but the cyclic ones) and u, and z.
struct Reduction {
  const SimTK::MultibodySystem* system;
  const SimTK::SimbodyMatterSubsystem* matter;
  SimTK::MobilizedBodyIndex base;
  int bq0 = -1, bu0 = -1;
  std::vector<int> qs, us;  // other coordinates and speeds kept
  int nz = 0;
  int size() const { return (base.isValid() ? 9 : 0) + int(qs.size() + us.size()) + nz; }

  Eigen::VectorXd fromState(const SimTK::State& s) const {
    Eigen::VectorXd r(size());
    int k = 0;
    if (base.isValid()) {
      const SimTK::MobilizedBody& mb = matter->getMobilizedBody(base);
      const Vec3 a = mb.getBodyRotation(s).convertThreeAxesRotationToThreeAngles(
          SimTK::BodyRotationSequence, SimTK::ZAxis, SimTK::YAxis, SimTK::XAxis);  // yaw, pitch, roll
      const SimTK::Rotation Rz(-a[0], SimTK::ZAxis);
      const SimTK::Vector& u = s.getU();
      const Vec3 w = Rz * Vec3(u[bu0], u[bu0 + 1], u[bu0 + 2]), v = Rz * Vec3(u[bu0 + 3], u[bu0 + 4], u[bu0 + 5]);
      r[k++] = s.getQ()[bq0 + 5];  // height
      r[k++] = a[2];
      r[k++] = a[1];
      for (int i = 0; i < 3; ++i) r[k++] = w[i];
      for (int i = 0; i < 3; ++i) r[k++] = v[i];
    }
    for (int i : qs) r[k++] = s.getQ()[i];
    for (int i : us) r[k++] = s.getU()[i];
    for (int i = 0; i < nz; ++i) r[k++] = s.getZ()[i];
    return r;
  }
  /// Writes r into s at zero yaw (x, y and cyclic coordinates kept).
  void toState(const Eigen::VectorXd& r, SimTK::State& s) const {
    int k = 0;
    if (base.isValid()) {
      const SimTK::MobilizedBody& mb = matter->getMobilizedBody(base);
      const double z = r[k++], roll = r[k++], pitch = r[k++];
      mb.setQToFitRotation(s, SimTK::Rotation(SimTK::BodyRotationSequence, pitch, SimTK::YAxis, roll, SimTK::XAxis));
      s.updQ()[bq0 + 5] = z;
      for (int i = 0; i < 6; ++i) s.updU()[bu0 + i] = r[k++];
    }
    for (int i : qs) s.updQ()[i] = r[k++];
    for (int i : us) s.updU()[i] = r[k++];
    for (int i = 0; i < nz; ++i) s.updZ()[i] = r[k++];
  }
  /// The state entry that reduced coordinate j is at zero yaw, when it is a
  /// single speed (base velocities, kept speeds) or z: 'u' or 'z' and its
  /// index; 'q' (index -1) for the coordinates (toState writes those).
  std::pair<char, int> entry(int j) const {
    const int nb = base.isValid() ? 9 : 0, nq = int(qs.size()), nu = int(us.size());
    if (nb && j >= 3 && j < 9) return {'u', bu0 + j - 3};
    if (j >= nb + nq && j < nb + nq + nu) return {'u', us[j - nb - nq]};
    if (j >= nb + nq + nu) return {'z', j - nb - nq - nu};
    return {'q', -1};
  }
  /// d r / dt from Simbody's forward dynamics at a state with zero yaw.
  Eigen::VectorXd rate(SimTK::State& s) const {
    system->realize(s, SimTK::Stage::Acceleration);
    Eigen::VectorXd d(size());
    int k = 0;
    if (base.isValid()) {
      const SimTK::Vector& u = s.getU();
      const SimTK::Vector& udot = s.getUDot();
      const Vec3 w(u[bu0], u[bu0 + 1], u[bu0 + 2]), v(u[bu0 + 3], u[bu0 + 4], u[bu0 + 5]);
      const SimTK::MobilizedBody& mb = matter->getMobilizedBody(base);
      const Vec3 a = mb.getBodyRotation(s).convertThreeAxesRotationToThreeAngles(
          SimTK::BodyRotationSequence, SimTK::ZAxis, SimTK::YAxis, SimTK::XAxis);
      const double pitch = a[1];
      // ZYX rates at zero yaw: w = (roll' cos(pitch), pitch', yaw' - roll' sin(pitch)).
      const double rollDot = w[0] / std::cos(pitch), pitchDot = w[1], yawDot = w[2] + rollDot * std::sin(pitch);
      const Vec3 ez(0, 0, 1);
      const Vec3 wdot = Vec3(udot[bu0], udot[bu0 + 1], udot[bu0 + 2]) - yawDot * SimTK::cross(ez, w);
      const Vec3 vdot = Vec3(udot[bu0 + 3], udot[bu0 + 4], udot[bu0 + 5]) - yawDot * SimTK::cross(ez, v);
      d[k++] = s.getQDot()[bq0 + 5];
      d[k++] = rollDot;
      d[k++] = pitchDot;
      for (int i = 0; i < 3; ++i) d[k++] = wdot[i];
      for (int i = 0; i < 3; ++i) d[k++] = vdot[i];
    }
    for (int i : qs) d[k++] = s.getQDot()[i];
    for (int i : us) d[k++] = s.getUDot()[i];
    for (int i = 0; i < nz; ++i) d[k++] = s.getZDot()[i];
    return d;
  }
};
}  // namespace

StabilityResult SteadyStateSolver::calcStability(const SteadyStateResult& steady, double tol) const {
  const LinearModel lin = calcLinearModel(steady, {}, {});
  StabilityResult out;
  out.dimension = int(lin.A.rows());
  out.equilibrium_residual = lastEquilibriumResidual_;
  const int D = out.dimension;
  double maxRe = -1e300;
  if (D > 0) {
    Eigen::EigenSolver<Eigen::MatrixXd> es(lin.A, false);
    for (int i = 0; i < D; ++i) {
      const std::complex<double> ev = es.eigenvalues()[i];
      out.eigenvalues.push_back(ev);
      if (ev.real() > maxRe) maxRe = ev.real(), out.least_damped = ev;
    }
  }
  std::sort(out.eigenvalues.begin(), out.eigenvalues.end(),
            [](const auto& a, const auto& b) { return a.real() > b.real(); });
  out.stable = D == 0 || maxRe < -tol;
  return out;
}

Eigen::MatrixXcd LinearModel::calcResponse(double w) const {
  const std::complex<double> jw(0, w);
  const int D = int(A.rows());
  const Eigen::MatrixXcd M = jw * Eigen::MatrixXcd::Identity(D, D) - A.cast<std::complex<double>>();
  const Eigen::MatrixXcd B = B0.cast<std::complex<double>>() + jw * B1.cast<std::complex<double>>() +
                             jw * jw * B2.cast<std::complex<double>>();
  const Eigen::MatrixXcd Dd = D0.cast<std::complex<double>>() + jw * D1.cast<std::complex<double>>() +
                              jw * jw * D2.cast<std::complex<double>>();
  return C.cast<std::complex<double>>() * M.partialPivLu().solve(B) + Dd;
}

LinearModel SteadyStateSolver::calcLinearModel(const SteadyStateResult& steady, const std::vector<LinearInput>& inputs,
                                               const std::vector<LinearOutput>& outputs) const {
  const SimTK::MultibodySystem& system = scene_.getSystem();
  const SimTK::SimbodyMatterSubsystem& matter = scene_.getMatter();
  SimTK::State s = steady.euler_state;
  for (int i = 0; i < np_ && i < int(steady.parameters.size()); ++i) problem_.parameters[i].set(s, steady.parameters[i]);
  s.invalidateAll(SimTK::Stage::Position);
  system.realize(s, SimTK::Stage::Instance);
  Reduction red;
  red.system = &system;
  red.matter = &matter;
  red.base = problem_.floating_base;
  std::vector<int> skipQ = problem_.cyclic_q, skipU;
  if (red.base.isValid()) {
    const SimTK::MobilizedBody& mb = matter.getMobilizedBody(red.base);
    red.bq0 = mb.getFirstQIndex(s);
    red.bu0 = mb.getFirstUIndex(s);
    for (int i = 0; i < 6; ++i) skipQ.push_back(red.bq0 + i), skipU.push_back(red.bu0 + i);
  }
  for (int i : qAll_)
    if (!contains(skipQ, i)) red.qs.push_back(i);
  for (int i = 0; i < nu_; ++i)
    if (!contains(skipU, i)) red.us.push_back(i);
  red.nz = nz_;
  // Start from the steady state at zero yaw.
  system.realize(s, SimTK::Stage::Position);
  const Eigen::VectorXd r0 = red.fromState(s);
  red.toState(r0, s);
  const int N = red.size();
  const int ni = int(inputs.size()), no = int(outputs.size());
  // The rates come from the scene's fastest forward dynamics of the same
  // equations: a state whose rows are solved densely where the scene offers
  // it (ConstraintRowsService::use_dense_rows; its rows' drift terms vanish
  // on the manifold and, to first order, along its tangents), Simbody's
  // rows otherwise. The tangents (below) come from Simbody's constraint errors.
  SimTK::State sr = s;
  if (scene_.hasService(kConstraintRowsService)) {
    scene_.getService<const ConstraintRowsService>(kConstraintRowsService)->use_dense_rows(sr);
    system.realize(sr, SimTK::Stage::Instance);
  }
  auto setInput = [&](int k, double v, double vd, double vdd) {
    for (SimTK::State* st : {&s, &sr}) {
      inputs[k].set(*st, v, vd, vdd);
      st->invalidateAll(SimTK::Stage::Position);
    }
  };

  // Tangent space of the constraint manifold: null space of d[qerr; uerr]/dr.
  const int nc = s.getNQErr() + s.getNUErr();
  Eigen::MatrixXd C(nc, N);
  auto constraintErrors = [&](SimTK::State& st) {
    system.realize(st, SimTK::Stage::Velocity);
    Eigen::VectorXd c(nc);
    for (int i = 0; i < st.getNQErr(); ++i) c[i] = st.getQErr()[i];
    for (int i = 0; i < st.getNUErr(); ++i) c[st.getNQErr() + i] = st.getUErr()[i];
    return c;
  };
  // A speed's or z's column perturbs that entry alone (at zero yaw the
  // reduced base velocities are the base's speeds), so Simbody keeps the
  // Position stage: the same numbers as through toState, without the
  // coordinates' realization.
  const double hc = 1e-7;
  for (int j = 0; j < N; ++j) {
    if (red.entry(j).first != 'q') continue;
    Eigen::VectorXd rp = r0, rm = r0;
    rp[j] += hc;
    rm[j] -= hc;
    red.toState(rp, s);
    const Eigen::VectorXd cp = constraintErrors(s);
    red.toState(rm, s);
    C.col(j) = (cp - constraintErrors(s)) / (2 * hc);
  }
  red.toState(r0, s);
  for (int j = 0; j < N; ++j) {
    const auto [kind, i] = red.entry(j);
    if (kind == 'q') continue;
    const double v0 = r0[j];
    auto set = [&](double v) {
      if (kind == 'u') s.updU()[i] = v;
      else s.updZ()[i] = v;
    };
    set(v0 + hc);
    const Eigen::VectorXd cp = constraintErrors(s);
    set(v0 - hc);
    C.col(j) = (cp - constraintErrors(s)) / (2 * hc);
    set(v0);
  }
  Eigen::MatrixXd T;
  Eigen::MatrixXd Cpinv = Eigen::MatrixXd::Zero(N, nc);  // pseudo-inverse of C
  if (nc > 0) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(C, Eigen::ComputeFullV | Eigen::ComputeFullU);
    const auto& sv = svd.singularValues();
    int rank = 0;
    for (int i = 0; i < sv.size(); ++i) rank += sv[i] > 1e-8 * sv[0];
    T = svd.matrixV().rightCols(N - rank);
    for (int i = 0; i < rank; ++i) Cpinv += svd.matrixV().col(i) * svd.matrixU().col(i).transpose() / sv[i];
  } else {
    T = Eigen::MatrixXd::Identity(N, N);
  }
  const int D = int(T.cols());
  // State rate and outputs at a reduced state (outputs need Acceleration: rate() realizes it).
  auto rateAndOutputs = [&](const Eigen::VectorXd& r) {
    red.toState(r, sr);
    Eigen::VectorXd d(N + no);
    d.head(N) = red.rate(sr);
    for (int k = 0; k < no; ++k) d[N + k] = outputs[k].calc(sr);
    return d;
  };
  red.toState(r0, sr);
  lastEquilibriumResidual_ = maxAbs(red.rate(sr));
  LinearModel lin;
  for (const auto& i : inputs) lin.inputs.push_back(i.name);
  for (const auto& o : outputs) lin.outputs.push_back(o.name);
  // A = T^T (d rate / d r) T and C by central differences along the tangent directions.
  Eigen::MatrixXd JT(N + no, D);
  const double h = 1e-6;
  for (int j = 0; j < D; ++j) JT.col(j) = (rateAndOutputs(r0 + h * T.col(j)) - rateAndOutputs(r0 - h * T.col(j))) / (2 * h);
  lin.A = T.transpose() * JT.topRows(N);
  lin.C = JT.bottomRows(no);
  lin.B0.resize(D, ni), lin.B1.resize(D, ni), lin.B2.resize(D, ni);
  lin.D0.resize(no, ni), lin.D1.resize(no, ni), lin.D2.resize(no, ni);
  for (int k = 0; k < ni; ++k) {
    const double hk = 1e-3 * inputs[k].typical;
    for (int level = 0; level < 3; ++level) {
      auto apply = [&](double sgn) {
        setInput(k, level == 0 ? sgn * hk : 0, level == 1 ? sgn * hk : 0, level == 2 ? sgn * hk : 0);
      };
      // The particular displacement that keeps the state on the moved constraint
      // manifold (the acceleration level moves no state): X = -C^+ dc/dv.
      Eigen::VectorXd X = Eigen::VectorXd::Zero(N);
      if (level < 2 && nc > 0) {
        red.toState(r0, s);
        apply(+1);
        const Eigen::VectorXd cp = constraintErrors(s);
        apply(-1);
        const Eigen::VectorXd cm = constraintErrors(s);
        X = -Cpinv * ((cp - cm) / (2 * hk));
      }
      apply(+1);
      const Eigen::VectorXd dp = rateAndOutputs(r0 + hk * X);
      apply(-1);
      const Eigen::VectorXd dm = rateAndOutputs(r0 - hk * X);
      const Eigen::VectorXd d = (dp - dm) / (2 * hk);
      Eigen::MatrixXd& B = level == 0 ? lin.B0 : level == 1 ? lin.B1 : lin.B2;
      Eigen::MatrixXd& Dm = level == 0 ? lin.D0 : level == 1 ? lin.D1 : lin.D2;
      B.col(k) = T.transpose() * d.head(N);
      Dm.col(k) = d.tail(no);
    }
    setInput(k, 0, 0, 0);
  }
  return lin;
}

// --- continuation and sensitivity ------------------------------------------------
std::vector<ContinuationPoint> followSteadyState(SteadyStateSolver& solver, const SimTK::State& start,
                                                 const std::vector<double>& values,
                                                 const std::function<void(SimTK::State&, double)>& setCondition,
                                                 const ContinuationOptions& options) {
  std::vector<ContinuationPoint> out;
  // Converged points along the branch (values and solutions), latest last;
  // intermediate points of a bisected step are kept here but not reported.
  std::vector<std::pair<double, SteadyStateResult>> branch;
  auto predict = [&](double v, SteadyStateResult& guess) {
    // Lagrange extrapolation through the last (up to three) branch points.
    const std::size_t k = std::min<std::size_t>(3, branch.size());
    if (k < 2) return;
    std::vector<double> vs;
    std::vector<Eigen::VectorXd> xs;
    for (std::size_t i = branch.size() - k; i < branch.size(); ++i) {
      vs.push_back(branch[i].first);
      xs.push_back(solver.getUnknowns(branch[i].second));
    }
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = i + 1; j < k; ++j)
        if (vs[i] == vs[j]) return;
    Eigen::VectorXd xp = Eigen::VectorXd::Zero(xs[0].size());
    for (std::size_t i = 0; i < k; ++i) {
      double w = 1;
      for (std::size_t j = 0; j < k; ++j)
        if (j != i) w *= (v - vs[j]) / (vs[i] - vs[j]);
      xp += w * xs[i];
    }
    solver.setGuess(xp, guess);
  };
  auto solveAt = [&](double v) {
    if (branch.empty()) {
      SimTK::State s = start;
      setCondition(s, v);
      return solver.solve(s);
    }
    SteadyStateResult guess = branch.back().second;
    setCondition(guess.euler_state, v);
    predict(v, guess);
    return solver.resolve(guess);
  };
  bool ended = false;
  for (double v : values) {
    ContinuationPoint p;
    p.value = v;
    if (ended) {
      p.failure = "the branch ended before this value (no steady state found by continuation)";
      out.push_back(std::move(p));
      continue;
    }
    // Try the full step; on failure, reach v by halving the step from the
    // last converged point, up to max_bisections times.
    double target = v;
    int halvings = 0;
    while (true) {
      try {
        SteadyStateResult r = solveAt(target);
        if (options.accept) {
          const std::string why = branch.empty() ? options.accept(nullptr, 0.0, r, target)
                                                 : options.accept(&branch.back().second, branch.back().first, r, target);
          if (!why.empty())
            throw Error("branch jump refused at " + formatValue(target) + ": " + why);
        }
        branch.emplace_back(target, r);
        if (target == v) {
          p.result = std::move(r);
          p.converged = true;
          break;
        }
        target = v;  // an intermediate point converged: try the rest
      } catch (const Error& e) {
        if (branch.empty() || halvings == options.max_bisections) {
          p.failure = e.what();
          break;
        }
        ++halvings;
        target = branch.back().first + 0.5 * (target - branch.back().first);
      }
    }
    if (!p.converged && options.stop_at_branch_end && !branch.empty()) ended = true;
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<double> calcSteadyStateSensitivity(
    SteadyStateSolver& solver, const SteadyStateResult& nominal, double p0, double typical,
    const std::function<void(SimTK::State&, double)>& setCondition,
    const std::function<std::vector<double>(const SimTK::State&)>& outputs, double h) {
  requireFinite(p0, "steady-state sensitivity parameter value");
  if (h <= 0) h = std::max(std::abs(p0), std::abs(typical)) * std::cbrt(1e-10);
  requirePositive(h, "steady-state sensitivity step h");
  auto at = [&](double p) {
    SteadyStateResult g = nominal;
    setCondition(g.euler_state, p);
    const SteadyStateResult r = solver.resolve(g);
    return outputs(r.state);
  };
  const std::vector<double> fp = at(p0 + h), fm = at(p0 - h);
  // Leave the scene's condition at its nominal value.
  SteadyStateResult g = nominal;
  setCondition(g.euler_state, p0);
  std::vector<double> d(fp.size());
  for (std::size_t i = 0; i < fp.size(); ++i) d[i] = (fp[i] - fm[i]) / (2 * h);  // (4.49)
  return d;
}

ArclengthResult continueSteadyState(SteadyStateSolver& solver, const SteadyStateResult& start, double value0,
                                    const std::function<void(SimTK::State&, double)>& setCondition,
                                    double value_scale, bool stability, const ArclengthOptions& options) {
  solver.beginDriven(start, setCondition, value_scale);
  ArclengthSystem sys;
  sys.x_scale = solver.getUnknownScales();
  sys.lambda_scale = value_scale;
  sys.r_scale = solver.getEquationScales();
  sys.residual = [&solver](const Eigen::VectorXd& x, double v) { return solver.calcDrivenEquations(x, v); };
  sys.jacobian = [&solver](const Eigen::VectorXd& x, double v, const Eigen::VectorXd& r) {
    return solver.calcDrivenJacobian(x, v, r);
  };
  sys.converged = [&solver](const Eigen::VectorXd& r) { return solver.meetsTolerances(r); };
  if (stability)
    sys.eigenvalues = [&solver, &options](const Eigen::VectorXd& x, double v) {
      return solver.calcStability(solver.makeDrivenResult(x, v), options.stability_tolerance).eigenvalues;
    };
  return continueArclength(sys, solver.getUnknowns(start), value0, options);
}

}  // namespace vdyn
