#include "vdyn/vehicles/reduced_dense.h"

#include <cmath>

#include "vdyn/core/error.h"
#include "vdyn/speed/speed_hold.h"

namespace vdyn {

using SimTK::Vec3;

void ReducedDenseRows::setRows(std::vector<Arm> arms, std::vector<Steer> steers, std::vector<Speed> speeds) {
  arms_ = std::move(arms);
  steers_ = std::move(steers);
  speeds_ = std::move(speeds);
}

void ReducedDenseRows::realizeTopology(SimTK::State& s) const {
  activeIndex_ = forces_->allocateDiscreteVariable(s, SimTK::Stage::Instance, new SimTK::Value<bool>(false));
  releasedIndex_ =
      forces_->allocateDiscreteVariable(s, SimTK::Stage::Instance, new SimTK::Value<std::vector<int>>());
  lambdaIndex_ = forces_->allocateCacheEntry(s, SimTK::Stage::Dynamics, new SimTK::Value<SimTK::Vector>());
}

double ReducedDenseRows::speedHoldForce(const SimTK::State& s, int k) const {
  if (!isActive(s)) throw Error("reduced dense dynamics: speedHoldForce in a state that is not dense");
  if (!isSpeedHoldEnabled(s, k)) return 0;
  const SimTK::Vector& lambda = SimTK::Value<SimTK::Vector>::downcast(forces_->getCacheEntry(s, lambdaIndex_)).get();
  // This element applies +G^T lambda (Simbody applies -G^T lambda for its rows);
  // the rows of released holds are left out.
  int row = int(arms_.size() * 2 + steers_.size());
  for (int j = 0; j < k; ++j) row += isSpeedHoldEnabled(s, j) ? 1 : 0;
  return lambda[row];
}

bool ReducedDenseRows::isSpeedHoldEnabled(const SimTK::State& s, int k) const {
  const auto& released = SimTK::Value<std::vector<int>>::downcast(forces_->getDiscreteVariable(s, releasedIndex_)).get();
  return !(k < int(released.size()) && released[k]);
}

void ReducedDenseRows::setSpeedHoldEnabled(SimTK::State& s, int k, bool enabled) const {
  auto& released = SimTK::Value<std::vector<int>>::updDowncast(forces_->updDiscreteVariable(s, releasedIndex_)).upd();
  if (int(released.size()) <= k) released.resize(k + 1, 0);
  released[k] = enabled ? 0 : 1;
}

bool ReducedDenseRows::isActive(const SimTK::State& s) const {
  return SimTK::Value<bool>::downcast(forces_->getDiscreteVariable(s, activeIndex_)).get();
}

void ReducedDenseRows::setActive(SimTK::State& s, bool active) const {
  SimTK::Value<bool>::updDowncast(forces_->updDiscreteVariable(s, activeIndex_)).upd() = active;
}

void ReducedDenseRows::evalRows(const SimTK::State& s) const {
  const double w = kBaumgarteRate_per_s;
  const SimTK::Vector& u = s.getU();
  rows_.resize(numRows());
  std::size_t i = 0;
  int k = 0;
  for (const Arm& a : arms_) {
    const int us = a.knuckle.getFirstUIndex(s);
    const double sq = a.knuckle.getOneQ(s, 0), su = u[us];
    // Lower arm: q_L = s.
    {
      RowEval& r = rows_[i++];
      const int ul = a.lower.getFirstUIndex(s);
      r.n = 2;
      r.u[0] = ul, r.g[0] = 1;
      r.u[1] = us, r.g[1] = -1;
      r.perr = a.lower.getOneQ(s, 0) - sq;
      r.verr = u[ul] - su;
      r.b = -2 * w * r.verr - w * w * r.perr;
    }
    // Upper arm: q_U = theta4(s); d2/dt2: u_U' - theta4' s'' - theta4'' s'^2 = 0.
    {
      RowEval& r = rows_[i++];
      const int uu = a.upper.getFirstUIndex(s);
      const Vec3 t4 = a.loop->calcUpperArmAngle(sq);
      r.n = 2;
      r.u[0] = uu, r.g[0] = 1;
      r.u[1] = us, r.g[1] = -t4[1];
      r.perr = a.upper.getOneQ(s, 0) - t4[0];
      r.verr = u[uu] - t4[1] * su;
      r.b = t4[2] * su * su - 2 * w * r.verr - w * w * r.perr;
    }
  }
  const double t = s.getTime();
  for (const Steer& st : steers_) {
    // delta of the knuckle's mobilizer is the angle of (A.1): delta = command.
    RowEval& r = rows_[i++];
    const int ud = st.knuckle.getFirstUIndex(s) + 1;
    if (st.command) {
      const SteerCommandValue c = st.command->calcAt(t);
      r.n = 1;
      r.u[0] = ud, r.g[0] = 1;
      r.perr = st.knuckle.getOneQ(s, 1) - c.angle_rad;
      r.verr = u[ud] - c.rate_rad_s;
      r.b = c.accel_rad_s2 - 2 * w * r.verr - w * w * r.perr;
    } else {
      // State-driven: delta = q_D, q_D'' prescribed (enters through udot0).
      const int uD = st.steer.getFirstUIndex(s);
      r.n = 2;
      r.u[0] = ud, r.g[0] = 1;
      r.u[1] = uD, r.g[1] = -1;
      r.perr = st.knuckle.getOneQ(s, 1) - st.steer.getOneQ(s, 0);
      r.verr = u[ud] - u[uD];
      r.b = -2 * w * r.verr - w * w * r.perr;
    }
  }
  for (const Speed& sp : speeds_) {
    if (!isSpeedHoldEnabled(s, k++)) continue;  // released: the vehicle coasts
    // SpeedHoldImpl's row on the Free mobilizer's u = [w_G, v_G] (chassis
    // origin velocity in Ground): G = (v_xi e_xi + v_eta e_eta) / U0 on v.
    RowEval& r = rows_[i++];
    const int u0 = sp.chassis.getFirstUIndex(s);
    const SimTK::Rotation& R = sp.chassis.getBodyRotation(s);
    const Vec3 wG(u[u0], u[u0 + 1], u[u0 + 2]), vG(u[u0 + 3], u[u0 + 4], u[u0 + 5]);
    const Vec3 ex = R.x(), ey = R.y();
    const double U0 = sp.plugin->getSpeed(s);
    const double vx = SimTK::dot(ex, vG), vy = SimTK::dot(ey, vG);
    const Vec3 g = (vx * ex + vy * ey) / U0;
    r.n = 3;
    for (int k = 0; k < 3; ++k) r.u[k] = u0 + 3 + k, r.g[k] = g[k];
    r.perr = 0;
    r.verr = (vx * vx + vy * vy - U0 * U0) / (2 * U0);
    const double bias =
        (vx * SimTK::dot(SimTK::cross(wG, ex), vG) + vy * SimTK::dot(SimTK::cross(wG, ey), vG)) / U0;
    r.b = -bias - w * r.verr;
  }
  rows_.resize(i);
}

std::pair<double, double> ReducedDenseRows::calcRowErrors(const SimTK::State& s) const {
  evalRows(s);
  double p = 0, v = 0;
  for (const RowEval& r : rows_) {
    p = std::max(p, std::abs(r.perr));
    v = std::max(v, std::abs(r.verr));
  }
  return {p, v};
}

void ReducedDenseRows::realizeDynamics(const SimTK::State& s) const {
  if (!isActive(s)) return;
  const auto& mbs = SimTK::MultibodySystem::downcast(matter_->getSystem());
  SimTK::Vector& f = mbs.updMobilityForces(s, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& F = mbs.getRigidBodyForces(s, SimTK::Stage::Dynamics);
  evalRows(s);
  const int m = int(rows_.size()), nu = s.getNU();
  matter_->calcAccelerationIgnoringConstraints(s, f, F, udot0_, A_GB_);
  Y_.resize(m);
  v_.resize(nu);
  v_ = 0;
  for (int i = 0; i < m; ++i) {
    const RowEval& r = rows_[i];
    for (int k = 0; k < r.n; ++k) v_[r.u[k]] = r.g[k];
    matter_->multiplyByMInv(s, v_, Y_[i]);
    for (int k = 0; k < r.n; ++k) v_[r.u[k]] = 0;
  }
  // A = G Y (symmetric positive definite), r = b - G udot0.
  A_.assign(std::size_t(m) * m, 0.0);
  r_.assign(m, 0.0);
  for (int i = 0; i < m; ++i) {
    const RowEval& ri = rows_[i];
    double gu = 0;
    for (int k = 0; k < ri.n; ++k) gu += ri.g[k] * udot0_[ri.u[k]];
    r_[i] = ri.b - gu;
    for (int j = 0; j <= i; ++j) {
      double a = 0;
      for (int k = 0; k < ri.n; ++k) a += ri.g[k] * Y_[j][ri.u[k]];
      A_[i * m + j] = a;
    }
  }
  // Cholesky A = L L^T in place (lower triangle), then the two solves.
  for (int j = 0; j < m; ++j) {
    double d = A_[j * m + j];
    for (int k = 0; k < j; ++k) d -= A_[j * m + k] * A_[j * m + k];
    if (!(d > 0))
      throw Error("reduced dense dynamics: the constraint rows are singular at t = " + formatValue(s.getTime()) + " s");
    d = std::sqrt(d);
    A_[j * m + j] = d;
    for (int i = j + 1; i < m; ++i) {
      double a = A_[i * m + j];
      for (int k = 0; k < j; ++k) a -= A_[i * m + k] * A_[j * m + k];
      A_[i * m + j] = a / d;
    }
  }
  for (int i = 0; i < m; ++i) {
    double a = r_[i];
    for (int k = 0; k < i; ++k) a -= A_[i * m + k] * r_[k];
    r_[i] = a / A_[i * m + i];
  }
  for (int i = m - 1; i >= 0; --i) {
    double a = r_[i];
    for (int k = i + 1; k < m; ++k) a -= A_[k * m + i] * r_[k];
    r_[i] = a / A_[i * m + i];
  }
  // f += G^T lambda.
  SimTK::Vector& lambda = SimTK::Value<SimTK::Vector>::updDowncast(forces_->updCacheEntry(s, lambdaIndex_)).upd();
  lambda.resize(m);
  for (int i = 0; i < m; ++i) lambda[i] = r_[i];
  for (int i = 0; i < m; ++i) {
    const RowEval& ri = rows_[i];
    for (int k = 0; k < ri.n; ++k) f[ri.u[k]] += ri.g[k] * r_[i];
  }
}

}  // namespace vdyn
