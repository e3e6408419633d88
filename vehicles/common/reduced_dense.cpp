#include "vdyn/vehicles/reduced_dense.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "vdyn/core/error.h"
#include "vdyn/speed/speed_hold.h"

namespace vdyn {

using SimTK::Vec3;

void ReducedDenseRows::setRows(std::vector<Arm> arms, std::vector<Steer> steers, std::vector<Speed> speeds,
                               std::vector<Law> laws) {
  arms_ = std::move(arms);
  steers_ = std::move(steers);
  speeds_ = std::move(speeds);
  laws_ = std::move(laws);
}

void ReducedDenseRows::realizeTopology(SimTK::State& s) const {
  activeIndex_ = forces_->allocateDiscreteVariable(s, SimTK::Stage::Instance, new SimTK::Value<bool>(false));
  releasedIndex_ =
      forces_->allocateDiscreteVariable(s, SimTK::Stage::Instance, new SimTK::Value<std::vector<int>>());
  lambdaIndex_ = forces_->allocateCacheEntry(s, SimTK::Stage::Dynamics, new SimTK::Value<SimTK::Vector>());
  solvedIndex_ = forces_->allocateCacheEntry(s, SimTK::Stage::Dynamics, new SimTK::Value<std::vector<double>>());
  workIndex_ = forces_->allocateCacheEntry(s, SimTK::Stage::Instance, new SimTK::Value<Work>());
  structureIndex_ = forces_->allocateLazyCacheEntry(s, SimTK::Stage::Instance, new SimTK::Value<Structure>());
}

ReducedDenseRows::Work& ReducedDenseRows::updWork(const SimTK::State& s) const {
  return SimTK::Value<Work>::updDowncast(forces_->updCacheEntry(s, workIndex_)).upd();
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

double ReducedDenseRows::solvedSteerAcceleration(const SimTK::State& s, int k) const {
  const Work& w = updWork(s);
  if (w.solving) return w.x.at(k);
  if (s.getSystemStage() < SimTK::Stage::Dynamics)
    throw Error("steering plugin '" + laws_.at(k).plugin->name() +
                "': its delta'' is solved by the vehicle's dense forward dynamics, known from Stage::Dynamics on "
                "(the state is at Stage::" + s.getSystemStage().getName() + ")");
  return SimTK::Value<std::vector<double>>::downcast(forces_->getCacheEntry(s, solvedIndex_)).get().at(k);
}

int ReducedDenseRows::lastLawSweeps(const SimTK::State& s) const {
  const auto& v = SimTK::Value<std::vector<double>>::downcast(forces_->getCacheEntry(s, solvedIndex_)).get();
  return v.size() > laws_.size() ? int(v.back()) : 0;
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

void ReducedDenseRows::evalRows(const SimTK::State& s, std::vector<RowEval>& rows) const {
  const double w = kBaumgarteRate_per_s;
  const double* u = s.getU().getContiguousScalarData();  // (the state's q and u are contiguous)
  const double* q = s.getQ().getContiguousScalarData();
  rows.resize(numRows());
  std::size_t i = 0;
  int k = 0;
  for (const Arm& a : arms_) {
    const int us = a.knuckle.getFirstUIndex(s);
    const double sq = q[a.knuckle.getFirstQIndex(s)], su = u[us];
    const int bk = a.knuckle.getMobilizedBodyIndex(), bl = a.lower.getMobilizedBodyIndex(),
              bu = a.upper.getMobilizedBodyIndex();
    // Lower arm: q_L = s.
    {
      RowEval& r = rows[i++];
      const int ul = a.lower.getFirstUIndex(s);
      r.n = 2;
      r.u[0] = ul, r.g[0] = 1, r.body[0] = bl, r.ux[0] = 0;
      r.u[1] = us, r.g[1] = -1, r.body[1] = bk, r.ux[1] = 0;
      r.perr = q[a.lower.getFirstQIndex(s)] - sq;
      r.verr = u[ul] - su;
      r.b = -2 * w * r.verr - w * w * r.perr;
    }
    // Upper arm: q_U = theta4(s); d2/dt2: u_U' - theta4' s'' - theta4'' s'^2 = 0.
    {
      RowEval& r = rows[i++];
      const int uu = a.upper.getFirstUIndex(s);
      const Vec3 t4 = a.mobilizer->getUpperArmAngle(s);
      r.n = 2;
      r.u[0] = uu, r.g[0] = 1, r.body[0] = bu, r.ux[0] = 0;
      r.u[1] = us, r.g[1] = -t4[1], r.body[1] = bk, r.ux[1] = 0;
      r.perr = q[a.upper.getFirstQIndex(s)] - t4[0];
      r.verr = u[uu] - t4[1] * su;
      r.b = t4[2] * su * su - 2 * w * r.verr - w * w * r.perr;
    }
  }
  const double t = s.getTime();
  for (const Steer& st : steers_) {
    // delta of the knuckle's mobilizer is the angle of (A.1): delta = command.
    RowEval& r = rows[i++];
    const int ud = st.knuckle.getFirstUIndex(s) + 1, bk = st.knuckle.getMobilizedBodyIndex();
    if (st.command) {
      const SteerCommandValue c = st.command->calcAt(t);
      r.n = 1;
      r.u[0] = ud, r.g[0] = 1, r.body[0] = bk, r.ux[0] = 1;
      r.perr = q[st.knuckle.getFirstQIndex(s) + 1] - c.angle_rad;
      r.verr = u[ud] - c.rate_rad_s;
      r.b = c.accel_rad_s2 - 2 * w * r.verr - w * w * r.perr;
    } else {
      // State-driven: delta = q_D, q_D'' prescribed (enters through udot0).
      const int uD = st.steer.getFirstUIndex(s);
      r.n = 2;
      r.u[0] = ud, r.g[0] = 1, r.body[0] = bk, r.ux[0] = 1;
      r.u[1] = uD, r.g[1] = -1, r.body[1] = st.steer.getMobilizedBodyIndex(), r.ux[1] = 0;
      r.perr = q[st.knuckle.getFirstQIndex(s) + 1] - q[st.steer.getFirstQIndex(s)];
      r.verr = u[ud] - u[uD];
      r.b = -2 * w * r.verr - w * w * r.perr;
    }
  }
  for (const Speed& sp : speeds_) {
    if (!isSpeedHoldEnabled(s, k++)) continue;  // released: the vehicle coasts
    // SpeedHoldImpl's row on the Free mobilizer's u = [w_G, v_G] (chassis
    // origin velocity in Ground): G = (v_xi e_xi + v_eta e_eta) / U0 on v.
    RowEval& r = rows[i++];
    const int u0 = sp.chassis.getFirstUIndex(s);
    const SimTK::Rotation& R = sp.chassis.getBodyRotation(s);
    const Vec3 wG(u[u0], u[u0 + 1], u[u0 + 2]), vG(u[u0 + 3], u[u0 + 4], u[u0 + 5]);
    const Vec3 ex = R.x(), ey = R.y();
    const double U0 = sp.plugin->getSpeed(s);
    const double vx = SimTK::dot(ex, vG), vy = SimTK::dot(ey, vG);
    const Vec3 g = (vx * ex + vy * ey) / U0;
    r.n = 3;
    for (int k = 0; k < 3; ++k)
      r.u[k] = u0 + 3 + k, r.g[k] = g[k], r.body[k] = sp.chassis.getMobilizedBodyIndex(), r.ux[k] = 3 + k;
    r.perr = 0;
    r.verr = (vx * vx + vy * vy - U0 * U0) / (2 * U0);
    const double bias =
        (vx * SimTK::dot(SimTK::cross(wG, ex), vG) + vy * SimTK::dot(SimTK::cross(wG, ey), vG)) / U0;
    r.b = -bias - w * r.verr;
  }
  for (const Law& l : laws_) {
    // u_D' = x_D: the right side is the law's delta'', set by solveLaws.
    RowEval& r = rows[i++];
    const SimTK::MobilizedBody& D = l.plugin->getSteerBody();
    r.n = 1;
    r.u[0] = D.getFirstUIndex(s), r.g[0] = 1, r.body[0] = D.getMobilizedBodyIndex(), r.ux[0] = 0;
    r.b = r.perr = r.verr = 0;
  }
  rows.resize(i);
}

std::pair<double, double> ReducedDenseRows::calcRowErrors(const SimTK::State& s) const {
  std::vector<RowEval> rows;
  evalRows(s, rows);
  double p = 0, v = 0;
  for (const RowEval& r : rows) {
    p = std::max(p, std::abs(r.perr));
    v = std::max(v, std::abs(r.verr));
  }
  return {p, v};
}

namespace {
// In-place Cholesky of the lower triangle of the n x n row-major a (stride
// ld); false if not positive definite.
bool cholesky(double* a, int n, int ld) {
  for (int j = 0; j < n; ++j) {
    double d = a[j * ld + j];
    for (int k = 0; k < j; ++k) d -= a[j * ld + k] * a[j * ld + k];
    if (!(d > 0)) return false;
    d = std::sqrt(d);
    a[j * ld + j] = d;
    for (int i = j + 1; i < n; ++i) {
      double x = a[i * ld + j];
      for (int k = 0; k < j; ++k) x -= a[i * ld + k] * a[j * ld + k];
      a[i * ld + j] = x / d;
    }
  }
  return true;
}
// x := L^-1 x (forward substitution with the factor of cholesky()).
void forwardSolve(const double* l, int n, int ld, double* x) {
  for (int i = 0; i < n; ++i) {
    double a = x[i];
    for (int k = 0; k < i; ++k) a -= l[i * ld + k] * x[k];
    x[i] = a / l[i * ld + i];
  }
}
// x := L^-T x.
void backSolve(const double* l, int n, int ld, double* x) {
  for (int i = n - 1; i >= 0; --i) {
    double a = x[i];
    for (int k = i + 1; k < n; ++k) a -= l[k * ld + i] * x[k];
    x[i] = a / l[i * ld + i];
  }
}
double dot(const SimTK::SpatialVec& a, const SimTK::SpatialVec& b) { return SimTK::dot(a[0], b[0]) + SimTK::dot(a[1], b[1]); }
}  // namespace

void ReducedDenseRows::formProducts(const SimTK::State& s, Work& w) const {
  const int m = int(w.rows.size()), nu = s.getNU();
  w.Y.resize(m);
  w.v.resize(nu);
  w.v = 0;
  for (int i = 0; i < m; ++i) {
    const RowEval& r = w.rows[i];
    for (int k = 0; k < r.n; ++k) w.v[r.u[k]] = r.g[k];
    matter_->multiplyByMInv(s, w.v, w.Y[i]);
    for (int k = 0; k < r.n; ++k) w.v[r.u[k]] = 0;
  }
  // A = G Y (symmetric positive definite), lower triangle.
  w.A.assign(std::size_t(m) * m, 0.0);
  for (int i = 0; i < m; ++i) {
    const RowEval& ri = w.rows[i];
    for (int j = 0; j <= i; ++j) {
      const double* y = w.Y[j].getContiguousScalarData();
      double a = 0;
      for (int k = 0; k < ri.n; ++k) a += ri.g[k] * y[ri.u[k]];
      w.A[i * m + j] = a;
    }
  }
}

const ReducedDenseRows::Structure& ReducedDenseRows::getStructure(const SimTK::State& s,
                                                                    const std::vector<RowEval>& rows) const {
  using SimTK::MobilizedBody;
  using SimTK::MobilizedBodyIndex;
  if (forces_->isCacheValueRealized(s, structureIndex_))
    return SimTK::Value<Structure>::downcast(forces_->getCacheEntry(s, structureIndex_)).get();
  Structure& st = SimTK::Value<Structure>::updDowncast(forces_->updCacheEntry(s, structureIndex_)).upd();
  st = Structure();
  forces_->markCacheValueRealized(s, structureIndex_);
  // The chassis: every entry's body is it or one of its children.
  int base = -1;
  for (const RowEval& r : rows)
    for (int k = 0; k < r.n; ++k) {
      const MobilizedBody& b = matter_->getMobilizedBody(MobilizedBodyIndex(r.body[k]));
      const MobilizedBody& p = b.getParentMobilizedBody();
      int c;
      if (p.isGround()) c = r.body[k];
      else if (p.getParentMobilizedBody().isGround()) c = p.getMobilizedBodyIndex();
      else return st;
      if (base >= 0 && c != base) return st;
      base = c;
    }
  if (base < 0) return st;
  st.chassis = &matter_->getMobilizedBody(MobilizedBodyIndex(base));
  if (st.chassis->getUDotMotionMethod(s) != SimTK::Motion::Free) return st;
  st.nc = st.chassis->getNumU(s);
  const int m = int(rows.size());
  st.entryChild.assign(std::size_t(3) * m, -1);
  for (int i = 0; i < m; ++i) {
    const RowEval& r = rows[i];
    for (int k = 0; k < r.n; ++k) {
      if (r.body[k] == base) continue;
      const MobilizedBody& B = matter_->getMobilizedBody(MobilizedBodyIndex(r.body[k]));
      int e = 0;
      while (e < int(st.children.size()) && st.children[e].body != &B) ++e;
      st.entryChild[3 * i + k] = e;
      if (e == int(st.children.size()))
        st.children.push_back({&B, B.getNumU(s), B.getUDotMotionMethod(s) != SimTK::Motion::Free});
    }
  }
  for (int i = 0; i < m; ++i)
    for (int k = 0; k < rows[i].n; ++k) {
      const int e = st.entryChild[3 * i + k];
      if (e < 0 || st.children[e].known) continue;
      for (int j = 0; j <= i; ++j)
        for (int l = 0; l < rows[j].n; ++l)
          if (st.entryChild[3 * j + l] == e) st.pairs.push_back({i, k, j, l, e});
    }
  st.blocks = true;
  return st;
}

// G M^-1 G^T from the articulated-body inertias, when every row touches
// only the chassis c (a child of Ground) and its children b. With M^-1 in
// the blocks of the articulated-body algorithm (u_c' = S^-1 (tau_c - L tau_b),
// u_b' = D^-1 tau_b - L^T u_c', zero velocities):
//   M^-1 = [ S^-1        -S^-1 L             ]
//          [ -L^T S^-1   D^-1 + L^T S^-1 L   ]
// S = H_c^T P_c H_c (the chassis's articulated inertia P_c on its
// mobilities), D = blockdiag(H_k^T P_k H_k) over the children k,
// L_k = H_c^T Phi_k P_k H_k D_k^-1 (Phi_k: spatial force at k's origin ->
// at the chassis's), so that with w_i = g_ic - L g_ib:
//   A_ij = g_ib^T D^-1 g_jb + w_i^T S^-1 w_j.
// A prescribed child (its u' known) has zero rows and columns in M^-1
// (multiplyByMInv's convention): its entries are left out.
bool ReducedDenseRows::formBlocks(const SimTK::State& s, Work& w) const {
  using SimTK::MobilizedBody;
  const Structure& st = getStructure(s, w.rows);
  if (!st.blocks) return false;
  const int m = int(w.rows.size()), nc = st.nc;
  const MobilizedBody& C = *st.chassis;
  SimTK::SpatialVec Hc[6];
  double S[36];
  {
    const SimTK::ArticulatedInertia& P = matter_->getArticulatedBodyInertia(s, C.getMobilizedBodyIndex());
    for (int j = 0; j < nc; ++j) Hc[j] = C.getHCol(s, SimTK::MobilizerUIndex(j));
    for (int j = 0; j < nc; ++j) {
      const SimTK::SpatialVec X = P * Hc[j];
      for (int i = j; i < nc; ++i) S[i * 6 + j] = dot(Hc[i], X);
    }
    if (!cholesky(S, nc, 6)) return false;
    std::copy(S, S + 36, w.S);
  }
  const Vec3 pc = C.getBodyOriginLocation(s);
  w.blocks.resize(st.children.size());
  for (std::size_t e = 0; e < st.children.size(); ++e) {
    const Structure::Child& ch = st.children[e];
    if (ch.known) continue;
    ChildBlocks& bb = w.blocks[e];
    const MobilizedBody& B = *ch.body;
    const SimTK::ArticulatedInertia& P = matter_->getArticulatedBodyInertia(s, B.getMobilizedBodyIndex());
    SimTK::SpatialVec H[6], X[6];
    double D[36];
    for (int j = 0; j < ch.nu; ++j) {
      H[j] = B.getHCol(s, SimTK::MobilizerUIndex(j));
      X[j] = P * H[j];
    }
    for (int j = 0; j < ch.nu; ++j)
      for (int l = j; l < ch.nu; ++l) D[l * 6 + j] = dot(H[l], X[j]);
    if (!cholesky(D, ch.nu, 6)) return false;
    for (int j = 0; j < ch.nu; ++j) {  // column j of D^-1
      double x[6] = {0, 0, 0, 0, 0, 0};
      x[j] = 1;
      forwardSolve(D, ch.nu, 6, x);
      backSolve(D, ch.nu, 6, x);
      for (int l = 0; l < ch.nu; ++l) bb.Dinv[l][j] = x[l];
    }
    const Vec3 rc = B.getBodyOriginLocation(s) - pc;
    for (int j = 0; j < ch.nu; ++j) {
      SimTK::SpatialVec Y(Vec3(0), Vec3(0));
      for (int l = 0; l < ch.nu; ++l) Y += X[l] * bb.Dinv[l][j];  // P H D^-1, at B's origin
      const SimTK::SpatialVec F(Y[0] + SimTK::cross(rc, Y[1]), Y[1]);  // at the chassis's origin
      for (int c = 0; c < nc; ++c) bb.L[c][j] = dot(Hc[c], F);
    }
  }
  // t_i = Ls^-1 w_i (S = Ls Ls^T), w_i = g_ic - L g_ib.
  w.t.assign(std::size_t(m) * 6, 0.0);
  for (int i = 0; i < m; ++i) {
    const RowEval& r = w.rows[i];
    double* t = &w.t[std::size_t(i) * 6];
    for (int k = 0; k < r.n; ++k) {
      const int e = st.entryChild[3 * i + k];
      if (e < 0) t[r.ux[k]] += r.g[k];
      else if (!st.children[e].known)
        for (int c = 0; c < nc; ++c) t[c] -= w.blocks[e].L[c][r.ux[k]] * r.g[k];
    }
    forwardSolve(S, nc, 6, t);
  }
  // A = t t^T + the children's g^T D^-1 g (lower triangle).
  w.A.assign(std::size_t(m) * m, 0.0);
  for (int i = 0; i < m; ++i) {
    const double* ti = &w.t[std::size_t(i) * 6];
    for (int j = 0; j <= i; ++j) {
      const double* tj = &w.t[std::size_t(j) * 6];
      double a = 0;
      for (int c = 0; c < nc; ++c) a += ti[c] * tj[c];
      w.A[i * m + j] = a;
    }
  }
  for (const Structure::Pair& p : st.pairs) {
    const RowEval &ri = w.rows[p.i], &rj = w.rows[p.j];
    w.A[p.i * m + p.j] += ri.g[p.k] * rj.g[p.l] * w.blocks[p.child].Dinv[ri.ux[p.k]][rj.ux[p.l]];
  }
  return true;
}

SimTK::Matrix ReducedDenseRows::calcRowMatrix(const SimTK::State& s, bool byProducts) const {
  Work w;
  evalRows(s, w.rows);
  if (byProducts) formProducts(s, w);
  else if (!formBlocks(s, w))
    throw Error("reduced dense dynamics: the rows touch bodies other than the chassis and its children");
  const int m = int(w.rows.size());
  SimTK::Matrix A(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j <= i; ++j) A(i, j) = A(j, i) = w.A[i * m + j];
  return A;
}

void ReducedDenseRows::realizeDynamics(const SimTK::State& s) const {
  if (!isActive(s)) return;
  const auto& mbs = SimTK::MultibodySystem::downcast(matter_->getSystem());
  SimTK::Vector& f = mbs.updMobilityForces(s, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& F = mbs.getRigidBodyForces(s, SimTK::Stage::Dynamics);
  Work& w = updWork(s);
  evalRows(s, w.rows);
  const int m = int(w.rows.size());
  matter_->calcAccelerationIgnoringConstraints(s, f, F, w.udot0, w.A_GB);
  w.haveS = formBlocks(s, w);
  if (!w.haveS) formProducts(s, w);
  // r = b - G udot0.
  const double* udot0 = w.udot0.getContiguousScalarData();
  w.r.assign(m, 0.0);
  for (int i = 0; i < m; ++i) {
    const RowEval& ri = w.rows[i];
    double gu = 0;
    for (int k = 0; k < ri.n; ++k) gu += ri.g[k] * udot0[ri.u[k]];
    w.r[i] = ri.b - gu;
  }
  // Cholesky A = L L^T in place (lower triangle), then the two solves.
  if (!cholesky(w.A.data(), m, m))
    throw Error("reduced dense dynamics: the constraint rows are singular at t = " + formatValue(s.getTime()) + " s");
  if (laws_.empty()) {
    forwardSolve(w.A.data(), m, m, w.r.data());
    backSolve(w.A.data(), m, m, w.r.data());
  } else {
    solveLaws(s, w);
  }
  // f += G^T lambda.
  SimTK::Vector& lambda = SimTK::Value<SimTK::Vector>::updDowncast(forces_->updCacheEntry(s, lambdaIndex_)).upd();
  lambda.resize(m);
  for (int i = 0; i < m; ++i) lambda[i] = w.r[i];
  for (int i = 0; i < m; ++i) {
    const RowEval& ri = w.rows[i];
    for (int k = 0; k < ri.n; ++k) f[ri.u[k]] += ri.g[k] * w.r[i];
  }
}

void ReducedDenseRows::solveLaws(const SimTK::State& s, Work& w) const {
  const int m = int(w.rows.size()), nL = int(laws_.size()), first = m - nL;
  const double* L = w.A.data();
  // lambda(x) = lam0 + sum_k x_k Lam_k.
  w.lam0 = w.r;
  forwardSolve(L, m, m, w.lam0.data());
  backSolve(L, m, m, w.lam0.data());
  w.Lam.assign(std::size_t(nL) * m, 0.0);
  for (int k = 0; k < nL; ++k) {
    double* e = &w.Lam[std::size_t(k) * m];
    e[first + k] = 1;
    forwardSolve(L, m, m, e);
    backSolve(L, m, m, e);
  }
  // The station a law reads: its acceleration a(x) = a0 + sum_k x_k c_k.
  const SteeringLaw* reader = nullptr;
  StationAccelerationInput in;
  for (const Law& l : laws_)
    if (l.plugin->getAccelerationLaw()->readsStationAcceleration(&in)) {
      if (reader)
        throw Error("reduced dense dynamics: steering laws '" + reader->name() + "' and '" +
                    l.plugin->getAccelerationLaw()->name() + "' both read a station's acceleration; one can");
      reader = l.plugin->getAccelerationLaw();
    }
  Vec3 a0(0);
  std::vector<Vec3> c(nL, Vec3(0));
  if (reader) {
    const Structure& st = getStructure(s, w.rows);
    if (!st.chassis || st.chassis->getMobilizedBodyIndex() != in.body)
      throw Error("reduced dense dynamics: steering law '" + reader->name() + "' reads the acceleration of body " +
                  std::to_string(int(in.body)) + "; the dense rows give that of the chassis (a child of Ground) only");
    const SimTK::MobilizedBody& C = *st.chassis;
    const int nc = st.nc, u0 = C.getFirstUIndex(s);
    // Z_i: the chassis's u' per unit lambda_i, S^-1 w_i = Ls^-T t_i (blocks)
    // or the chassis's share of M^-1 g_i (products).
    w.Z.assign(std::size_t(m) * 6, 0.0);
    for (int i = 0; i < m; ++i) {
      double* z = &w.Z[std::size_t(i) * 6];
      if (w.haveS) {
        for (int j = 0; j < nc; ++j) z[j] = w.t[std::size_t(i) * 6 + j];
        backSolve(w.S, nc, 6, z);
      } else {
        for (int j = 0; j < nc; ++j) z[j] = w.Y[i][u0 + j];
      }
    }
    // The chassis's spatial acceleration: A_GB of udot0 plus H_c du (a child
    // of Ground: A = H u' + the velocity terms, which udot0's A_GB holds).
    auto spatial = [&](const double* lam) {
      double du[6] = {0, 0, 0, 0, 0, 0};
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < nc; ++j) du[j] += lam[i] * w.Z[std::size_t(i) * 6 + j];
      SimTK::SpatialVec A(Vec3(0), Vec3(0));
      for (int j = 0; j < nc; ++j) A += C.getHCol(s, SimTK::MobilizerUIndex(j)) * du[j];
      return A;
    };
    const Vec3 r = C.getBodyRotation(s) * in.station_B, om = C.getBodyAngularVelocity(s);
    const SimTK::SpatialVec A0 = w.A_GB[C.getMobilizedBodyIndex()] + spatial(w.lam0.data());
    a0 = A0[1] + SimTK::cross(A0[0], r) + SimTK::cross(om, SimTK::cross(om, r));
    for (int k = 0; k < nL; ++k) {
      const SimTK::SpatialVec B = spatial(&w.Lam[std::size_t(k) * m]);
      c[k] = B[1] + SimTK::cross(B[0], r);
    }
  }
  // Gauss-Seidel sweeps over the laws (the others' delta'' read through
  // ExternalSolve: w.x while solving), accelerated: a sweep maps its start x
  // to g, and the next sweep starts from the combination of the last sweeps'
  // g that makes their combined residual g - x least (Anderson acceleration
  // with up to nL differences kept (8 at most): for laws affine in x'' and in the other
  // laws' delta'', as the path and rear-steer laws are, the start of sweep
  // nL + 2 is the fixed point to rounding, and that sweep confirms it, whether
  // or not plain sweeps would contract). The result is the last sweep's g,
  // accepted as before when it moved less than 1e-10 (1 + |delta''|) from its
  // start; laws that do not settle end in an Error after 50 sweeps.
  struct Solving {
    Work& w;
    ~Solving() { w.solving = false; }
  } solving{w};
  w.x.assign(nL, 0.0);
  w.start.assign(nL, 0.0);
  w.f.resize(nL);
  w.gPrev.resize(nL);
  w.fPrev.resize(nL);
  w.dG.clear();
  w.dF.clear();
  w.solving = true;
  constexpr int kMaxSweeps = 50;
  constexpr double kTolerance = 1e-10;  // relative to 1 + |x|, rad/s^2: above the laws' rounding (1e-12 seen)
  const int memory = std::min(nL, 8);  // differences kept
  int sweeps = 0, kept = 0;
  double change = 0;
  for (;;) {
    if (++sweeps > kMaxSweeps)
      throw Error("reduced dense dynamics: the steering laws' delta'' did not settle in " + std::to_string(kMaxSweeps) +
                  " sweeps at t = " + formatValue(s.getTime()) + " s (last relative change " + formatValue(change) + ")");
    w.x = w.start;
    change = 0;
    for (int k = 0; k < nL; ++k) {
      const SteeringLaw* law = laws_[k].plugin->getAccelerationLaw();
      double v;
      if (law == reader) {
        Vec3 a = a0;
        for (int j = 0; j < nL; ++j) a += w.x[j] * c[j];
        v = law->calcAccelerationGiven(s, a);
      } else {
        v = law->calcAcceleration(s);
      }
      w.f[k] = v - w.start[k];
      change = std::max(change, std::abs(w.f[k]) / (1 + std::abs(v)));
      w.x[k] = v;
    }
    if (change <= kTolerance) break;
    // The next start: g - dG gamma, gamma the least-squares solution of
    // dF gamma = f over the kept differences (w.dF, w.dG: nL x kept, by column).
    if (sweeps > 1) {
      if (kept == memory) {  // the oldest difference out
        w.dG.erase(w.dG.begin(), w.dG.begin() + nL);
        w.dF.erase(w.dF.begin(), w.dF.begin() + nL);
        --kept;
      }
      w.dG.resize(std::size_t(kept + 1) * nL);
      w.dF.resize(std::size_t(kept + 1) * nL);
      for (int k = 0; k < nL; ++k) {
        w.dG[std::size_t(kept) * nL + k] = w.x[k] - w.gPrev[k];
        w.dF[std::size_t(kept) * nL + k] = w.f[k] - w.fPrev[k];
      }
      ++kept;
    }
    w.gPrev = w.x;
    w.fPrev = w.f;
    w.start = w.x;
    if (kept > 0) {
      // Eigen's full-pivot LU on the normal equations (at most 8 x 8: no heap);
      // a rank below kept (pivots under 1e-12 of the largest) drops the history.
      using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 8, 8>;
      const Eigen::Map<const Eigen::MatrixXd> dF(w.dF.data(), nL, kept), dG(w.dG.data(), nL, kept);
      const Eigen::Map<const Eigen::VectorXd> f(w.f.data(), nL);
      const Small M = dF.transpose() * dF;
      Eigen::FullPivLU<Small> lu(M);
      lu.setThreshold(1e-12);
      if (lu.rank() < kept) {
        kept = 0;
        w.dG.clear();
        w.dF.clear();
      } else {
        using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;
        const SmallVector b = dF.transpose() * f;
        const SmallVector gamma = lu.solve(b);
        Eigen::Map<Eigen::VectorXd>(w.start.data(), nL).noalias() -= dG * gamma;
      }
    }
  }
  for (int i = 0; i < m; ++i) {
    double l = w.lam0[i];
    for (int k = 0; k < nL; ++k) l += w.x[k] * w.Lam[std::size_t(k) * m + i];
    w.r[i] = l;
  }
  std::vector<double>& out = SimTK::Value<std::vector<double>>::updDowncast(forces_->updCacheEntry(s, solvedIndex_)).upd();
  out = w.x;
  out.push_back(sweeps);
}

}  // namespace vdyn
