#include "vdyn/vehicles/reduced_wishbone.h"

#include <cmath>
#include <map>

#include "vdyn/core/error.h"
#include "wishbone_corner.h"

namespace vdyn {

using SimTK::Vec3;

// ---------------------------------------------------------------------------
// Jet arithmetic (value, gradient, Hessian; h = [d00, d01, d11]).
namespace {
Jet2 operator+(const Jet2& a, const Jet2& b) {
  Jet2 r(a.v + b.v);
  for (int i = 0; i < 2; ++i) r.d[i] = a.d[i] + b.d[i];
  for (int i = 0; i < 3; ++i) r.h[i] = a.h[i] + b.h[i];
  return r;
}
Jet2 operator-(const Jet2& a, const Jet2& b) {
  Jet2 r(a.v - b.v);
  for (int i = 0; i < 2; ++i) r.d[i] = a.d[i] - b.d[i];
  for (int i = 0; i < 3; ++i) r.h[i] = a.h[i] - b.h[i];
  return r;
}
Jet2 operator-(const Jet2& a) { return Jet2(0.0) - a; }
Jet2 operator*(const Jet2& a, const Jet2& b) {
  Jet2 r(a.v * b.v);
  for (int i = 0; i < 2; ++i) r.d[i] = a.d[i] * b.v + a.v * b.d[i];
  r.h[0] = a.h[0] * b.v + 2 * a.d[0] * b.d[0] + a.v * b.h[0];
  r.h[1] = a.h[1] * b.v + a.d[0] * b.d[1] + a.d[1] * b.d[0] + a.v * b.h[1];
  r.h[2] = a.h[2] * b.v + 2 * a.d[1] * b.d[1] + a.v * b.h[2];
  return r;
}
Jet2 operator*(double a, const Jet2& b) {
  Jet2 r(a * b.v);
  for (int i = 0; i < 2; ++i) r.d[i] = a * b.d[i];
  for (int i = 0; i < 3; ++i) r.h[i] = a * b.h[i];
  return r;
}
/// f(a) given f, f', f'' at a.v.
Jet2 chain(const Jet2& a, double f, double f1, double f2) {
  Jet2 r(f);
  for (int i = 0; i < 2; ++i) r.d[i] = f1 * a.d[i];
  r.h[0] = f1 * a.h[0] + f2 * a.d[0] * a.d[0];
  r.h[1] = f1 * a.h[1] + f2 * a.d[0] * a.d[1];
  r.h[2] = f1 * a.h[2] + f2 * a.d[1] * a.d[1];
  return r;
}
Jet2 operator/(const Jet2& a, const Jet2& b) {
  const double x = b.v;
  return a * chain(b, 1 / x, -1 / (x * x), 2 / (x * x * x));
}
Jet2 sqrt(const Jet2& a) {
  const double r = std::sqrt(a.v);
  return chain(a, r, 0.5 / r, -0.25 / (r * a.v));
}
Jet2 sin(const Jet2& a) { return chain(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v)); }
Jet2 cos(const Jet2& a) { return chain(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v)); }
Jet2 acos(const Jet2& a) {
  const double w = 1 - a.v * a.v;
  return chain(a, std::acos(a.v), -1 / std::sqrt(w), -a.v / (w * std::sqrt(w)));
}
/// atan2(y, x): theta_j = (x y_j - y x_j) / r2, differentiated once more.
Jet2 atan2(const Jet2& y, const Jet2& x) {
  Jet2 r(std::atan2(y.v, x.v));
  const double r2 = x.v * x.v + y.v * y.v;
  double N[2], dr2[2];
  for (int j = 0; j < 2; ++j) {
    N[j] = x.v * y.d[j] - y.v * x.d[j];
    dr2[j] = 2 * (x.v * x.d[j] + y.v * y.d[j]);
    r.d[j] = N[j] / r2;
  }
  auto hess = [&](int j, int k, int hk) {
    const double dN = x.d[k] * y.d[j] + x.v * y.h[hk] - y.d[k] * x.d[j] - y.v * x.h[hk];
    return (dN * r2 - N[j] * dr2[k]) / (r2 * r2);
  };
  r.h[0] = hess(0, 0, 0);
  r.h[1] = hess(0, 1, 1);
  r.h[2] = hess(1, 1, 2);
  return r;
}

struct JV {
  Jet2 x, y, z;
  Jet2& operator[](int i) { return i == 0 ? x : i == 1 ? y : z; }
  const Jet2& operator[](int i) const { return i == 0 ? x : i == 1 ? y : z; }
};
JV jv(const Vec3& v) { return {Jet2(v[0]), Jet2(v[1]), Jet2(v[2])}; }
JV operator+(const JV& a, const JV& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
JV operator-(const JV& a, const JV& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
JV operator*(const Jet2& s, const JV& a) { return {s * a.x, s * a.y, s * a.z}; }
Jet2 dot(const JV& a, const JV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
JV cross(const JV& a, const JV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// M v for a constant matrix.
JV mul(const SimTK::Mat33& M, const JV& v) {
  JV r;
  for (int i = 0; i < 3; ++i) r[i] = M(i, 0) * v.x + M(i, 1) * v.y + M(i, 2) * v.z;
  return r;
}
/// Rodrigues: w turned by phi about the unit axis k.
JV rotate(const JV& k, const Jet2& c, const Jet2& sn, const JV& w) {
  return c * w + sn * cross(k, w) + (dot(k, w) * (Jet2(1.0) - c)) * k;
}

double wrapToPi(double a) { return std::remainder(a, 2 * SimTK::Pi); }
}  // namespace

// ---------------------------------------------------------------------------
WishboneLoop::WishboneLoop(const DoubleWishboneParams& p) {
  const SimTK::UnitVec3 a1 = p.lower_pivot.axis(), a4 = p.upper_pivot.axis();
  // The Pins of buildDoubleWishbone: X_C,arm(theta) = F Rz(theta) M^-1.
  const SimTK::Transform F1 = pinFrame(p.lower_pivot.parent_point_m, a1), M1 = pinFrame(p.lower_pivot.child_point_m, a1);
  const SimTK::Transform F4 = pinFrame(p.upper_pivot.parent_point_m, a4), M4 = pinFrame(p.upper_pivot.child_point_m, a4);
  P1_ = F1.p();
  R1_ = F1.R().asMat33();
  m1_ = ~M1 * p.lower_ball.parent_point_m;
  P4_ = F4.p();
  R4_ = F4.R().asMat33();
  m4_ = ~M4 * p.upper_ball.parent_point_m;
  lK_ = p.lower_ball.child_point_m;
  const Vec3 k = p.upper_ball.child_point_m - p.lower_ball.child_point_m;
  d_ = k.norm();
  kK_ = k / d_;
  spinK_ = SimTK::UnitVec3(p.wheel_spin_axis).asVec3();
  // Branches: at s = delta = 0 the upper-arm angle nearest zero (offset by
  // a multiple of 2 pi so that it is the Pin's angle) and the knuckle
  // orientation nearest the tabulated one (the identity: body axes parallel
  // to the chassis axes). Fixed from then on, so the solution is continuous.
  double best = 1e9, bestSign = 1, bestOffset = 0;
  for (double sg : {1.0, -1.0}) {
    sign4_ = sg;
    offset4_ = 0;
    const double t = solve(Jet2(0.0), Jet2(0.0), true).theta4.v;
    if (std::abs(wrapToPi(t)) < best) {
      best = std::abs(wrapToPi(t));
      bestSign = sg;
      bestOffset = wrapToPi(t) - t;
    }
  }
  sign4_ = bestSign;
  offset4_ = bestOffset;
  double bestAngle = 1e9;
  for (double sg : {1.0, -1.0}) {
    signPhi_ = sg;
    const double ang = calcTransform(0, 0).R().convertRotationToAngleAxis()[0];
    if (std::abs(ang) < bestAngle) {
      bestAngle = std::abs(ang);
      bestSign = sg;
    }
  }
  signPhi_ = bestSign;
  offsetPhi_ = 0;
}

WishboneLoop::Pose WishboneLoop::solve(const Jet2& s, const Jet2& delta, bool upperOnly) const {
  Pose out;
  // Lower ball centre L(s).
  const Jet2 cs = cos(s), ss = sin(s);
  const JV m1r = {cs * m1_[0] - ss * m1_[1], ss * m1_[0] + cs * m1_[1], Jet2(m1_[2])};
  const JV L = jv(P1_) + mul(R1_, m1r);
  // Upper arm angle: |U(theta4) - L| = d, in the upper pivot frame F4.
  const JV w = mul(R4_.transpose(), L - jv(P4_));
  const double ux = m4_[0], uy = m4_[1], uz = m4_[2];
  const Jet2 alpha = w.x * ux + w.y * uy, beta = w.y * ux - w.x * uy;
  const Jet2 dz = Jet2(uz) - w.z;
  const Jet2 gamma = 0.5 * (Jet2(ux * ux + uy * uy - d_ * d_) + dz * dz + w.x * w.x + w.y * w.y);
  const Jet2 rho = sqrt(alpha * alpha + beta * beta);
  const Jet2 ratio = gamma / rho;
  if (!(std::abs(ratio.v) < 1))
    throw Error("reduced corner: the loop cannot close at s = " + formatValue(s.v) +
                " rad (the upper ball is out of reach)");
  out.theta4 = atan2(beta, alpha) + sign4_ * acos(ratio) + Jet2(offset4_);
  if (upperOnly) return out;
  const Jet2 c4 = cos(out.theta4), s4 = sin(out.theta4);
  const JV m4r = {c4 * ux - s4 * uy, s4 * ux + c4 * uy, Jet2(uz)};
  const JV U = jv(P4_) + mul(R4_, m4r);
  // Kingpin k and the smallest rotation R0 carrying the knuckle's kK onto it.
  const JV kv = U - L;
  const JV k = (Jet2(1.0) / sqrt(dot(kv, kv))) * kv;
  const JV kKj = jv(kK_);
  const JV c = cross(kKj, k);
  const Jet2 inv1 = Jet2(1.0) / (Jet2(1.0) + dot(kKj, k));
  auto R0 = [&](const Vec3& v0) {
    const JV v = jv(v0);
    const JV cv = cross(c, v);
    return v + cv + inv1 * cross(c, cv);
  };
  // Turn phi about k so that x . spin = -sin(delta) (A.1): P cos + Q sin = Rr.
  const JV v = R0(spinK_);
  const Jet2 vk = dot(k, v);
  const Jet2 P = v.x - vk * k.x;  // x . (v - k (k . v))
  const Jet2 Q = cross(k, v).x;
  const Jet2 Rr = -sin(delta) - vk * k.x;
  const Jet2 rp = sqrt(P * P + Q * Q);
  const Jet2 ratioPhi = Rr / rp;
  if (!(std::abs(ratioPhi.v) < 1))
    throw Error("reduced corner: steering angle " + formatValue(delta.v) + " rad is out of the knuckle's reach at s = " +
                formatValue(s.v) + " rad");
  const Jet2 phi = atan2(Q, P) + signPhi_ * acos(ratioPhi) + Jet2(offsetPhi_);
  const Jet2 cp = cos(phi), sp = sin(phi);
  for (int j = 0; j < 3; ++j) {
    const JV col = rotate(k, cp, sp, R0(Vec3(j == 0, j == 1, j == 2)));
    for (int i = 0; i < 3; ++i) out.R[i][j] = col[i];
  }
  // Knuckle origin: L - R lK.
  for (int i = 0; i < 3; ++i)
    out.p[i] = L[i] - (lK_[0] * out.R[i][0] + lK_[1] * out.R[i][1] + lK_[2] * out.R[i][2]);
  return out;
}

WishboneLoop::Pose WishboneLoop::calcPose(double s, double delta) const {
  return solve(Jet2::variable(s, 0), Jet2::variable(delta, 1), false);
}

SimTK::Transform WishboneLoop::calcTransform(double s, double delta) const {
  const Pose P = solve(Jet2(s), Jet2(delta), false);
  SimTK::Mat33 R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = P.R[i][j].v;
  return SimTK::Transform(SimTK::Rotation(R, true), Vec3(P.p[0].v, P.p[1].v, P.p[2].v));
}

Vec3 WishboneLoop::calcUpperArmAngle(double s) const {
  const Jet2 t = solve(Jet2::variable(s, 0), Jet2(0.0), true).theta4;
  return Vec3(t.v, t.d[0], t.h[0]);
}

// ---------------------------------------------------------------------------
ReducedKnuckleMobilizer::ReducedKnuckleMobilizer(SimTK::SimbodyMatterSubsystem& matter, const WishboneLoop& loop)
    : Implementation(matter, 2, 2, 0), loop_(loop), matter_(&matter) {}

void ReducedKnuckleMobilizer::realizeTopology(SimTK::State& s) const {
  kinematicsIndex_ = matter_->allocateCacheEntry(s, SimTK::Stage::Model, new SimTK::Value<Kinematics>());
}

const ReducedKnuckleMobilizer::Kinematics& ReducedKnuckleMobilizer::getKinematics(const SimTK::State& s, double q0,
                                                                                   double q1) const {
  Kinematics& K = SimTK::Value<Kinematics>::updDowncast(matter_->updCacheEntry(s, kinematicsIndex_)).upd();
  if (!(q0 == K.q0 && q1 == K.q1)) K = calcKinematics(q0, q1);
  return K;
}

ReducedKnuckleMobilizer::Kinematics ReducedKnuckleMobilizer::calcKinematics(double q0, double q1) const {
  const WishboneLoop::Pose P = loop_.calcPose(q0, q1);
  Kinematics K;
  SimTK::Mat33 R, dR[2], ddR[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Jet2& e = P.R[i][j];
      R(i, j) = e.v;
      dR[0](i, j) = e.d[0];
      dR[1](i, j) = e.d[1];
      for (int h = 0; h < 3; ++h) ddR[h](i, j) = e.h[h];
    }
  K.X = SimTK::Transform(SimTK::Rotation(R, true), Vec3(P.p[0].v, P.p[1].v, P.p[2].v));
  K.theta4 = Vec3(P.theta4.v, P.theta4.d[0], P.theta4.h[0]);
  const SimTK::Mat33 Rt = R.transpose();
  // w_j = vee(dR_j R^T); d w_j / d q_k = vee(d2R_jk R^T + dR_j dR_k^T).
  auto vee = [](const SimTK::Mat33& W) {
    return Vec3(0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1)));
  };
  for (int j = 0; j < 2; ++j) {
    K.H[j] = SimTK::SpatialVec(vee(dR[j] * Rt), Vec3(P.p[0].d[j], P.p[1].d[j], P.p[2].d[j]));
    for (int k = 0; k < 2; ++k) {
      const int hk = j + k;
      K.dH[j][k] = SimTK::SpatialVec(vee(ddR[hk] * Rt + dR[j] * dR[k].transpose()),
                                     Vec3(P.p[0].second(j, k), P.p[1].second(j, k), P.p[2].second(j, k)));
    }
  }
  K.q0 = q0;
  K.q1 = q1;
  return K;
}

const ReducedKnuckleMobilizer::Kinematics& ReducedKnuckleMobilizer::atState(const SimTK::State& s) const {
  const SimTK::MobilizedBody& mb = matter_->getMobilizedBody(mbx_);
  return getKinematics(s, mb.getOneQ(s, 0), mb.getOneQ(s, 1));
}

SimTK::Transform ReducedKnuckleMobilizer::calcMobilizerTransformFromQ(const SimTK::State& s, int nq,
                                                                     const SimTK::Real* q) const {
  assert(nq == 2);
  (void)nq;
  return getKinematics(s, q[0], q[1]).X;
}

SimTK::SpatialVec ReducedKnuckleMobilizer::multiplyByHMatrix(const SimTK::State& s, int nu, const SimTK::Real* u) const {
  assert(nu == 2);
  (void)nu;
  const Kinematics& K = atState(s);
  return K.H[0] * u[0] + K.H[1] * u[1];
}

void ReducedKnuckleMobilizer::multiplyByHTranspose(const SimTK::State& s, const SimTK::SpatialVec& F, int nu,
                                                   SimTK::Real* f) const {
  assert(nu == 2);
  (void)nu;
  const Kinematics& K = atState(s);
  for (int j = 0; j < 2; ++j) f[j] = SimTK::dot(K.H[j][0], F[0]) + SimTK::dot(K.H[j][1], F[1]);
}

// HDot = sum_k u_k dH/dq_k, u the state's speeds.
SimTK::SpatialVec ReducedKnuckleMobilizer::multiplyByHDotMatrix(const SimTK::State& s, int nu,
                                                                const SimTK::Real* in) const {
  assert(nu == 2);
  (void)nu;
  const Kinematics& K = atState(s);
  const SimTK::MobilizedBody& mb = matter_->getMobilizedBody(mbx_);
  const double u0 = mb.getOneU(s, 0), u1 = mb.getOneU(s, 1);
  SimTK::SpatialVec r(Vec3(0), Vec3(0));
  for (int j = 0; j < 2; ++j) r += in[j] * (K.dH[j][0] * u0 + K.dH[j][1] * u1);
  return r;
}

void ReducedKnuckleMobilizer::multiplyByHDotTranspose(const SimTK::State& s, const SimTK::SpatialVec& F, int nu,
                                                      SimTK::Real* f) const {
  assert(nu == 2);
  (void)nu;
  const Kinematics& K = atState(s);
  const SimTK::MobilizedBody& mb = matter_->getMobilizedBody(mbx_);
  const double u0 = mb.getOneU(s, 0), u1 = mb.getOneU(s, 1);
  for (int j = 0; j < 2; ++j) {
    const SimTK::SpatialVec Hd = K.dH[j][0] * u0 + K.dH[j][1] * u1;
    f[j] = SimTK::dot(Hd[0], F[0]) + SimTK::dot(Hd[1], F[1]);
  }
}

// ---------------------------------------------------------------------------
namespace {
/// The plane of an arm through its pivot axis and its ball point (arm frame):
/// the knuckle's ball point lies in it exactly when the arm's angle is the
/// loop's (the knuckle point is on the arm's circle by construction).
ArmPlanesImpl::Row armRow(const SimTK::MobilizedBody& arm, const JointParams& pivot, const Vec3& armBall,
                          const SimTK::MobilizedBody& knuckle, const Vec3& knuckleBall, const std::string& what) {
  const Vec3 axis = pivot.child_axis_point_m - pivot.child_point_m;
  const Vec3 n = SimTK::cross(axis, armBall - pivot.child_point_m);
  if (!(n.norm() > 1e-9 * axis.norm() * (armBall - pivot.child_point_m).norm()))
    throw Error("reduced corner: the " + what + " ball joint lies on the arm's pivot axis");
  const SimTK::UnitVec3 normal(n);
  return {arm, knuckle, normal, SimTK::dot(normal.asVec3(), pivot.child_point_m), knuckleBall};
}
}  // namespace

std::vector<ArmPlanesImpl::Row> armPlaneRows(const DoubleWishboneParams& p, const SimTK::MobilizedBody& lowerArm,
                                             const SimTK::MobilizedBody& knuckle,
                                             const SimTK::MobilizedBody& upperArm) {
  return {armRow(lowerArm, p.lower_pivot, p.lower_ball.parent_point_m, knuckle, p.lower_ball.child_point_m, "lower"),
          armRow(upperArm, p.upper_pivot, p.upper_ball.parent_point_m, knuckle, p.upper_ball.child_point_m, "upper")};
}

ArmPlanesImpl::ArmPlanesImpl(SimTK::SimbodyMatterSubsystem& matter, const std::vector<Row>& rows)
    : Implementation(matter, int(rows.size()), 0, 0) {
  std::map<SimTK::MobilizedBodyIndex, SimTK::ConstrainedBodyIndex> index;
  auto body = [&](const SimTK::MobilizedBody& b) {
    const auto it = index.find(b.getMobilizedBodyIndex());
    if (it != index.end()) return it->second;
    return index[b.getMobilizedBodyIndex()] = addConstrainedBody(b);
  };
  for (const Row& r : rows) rows_.push_back({body(r.arm), body(r.knuckle), r.normal_arm, r.height_m, r.point_knuckle});
}

void ArmPlanesImpl::calcPositionErrors(const SimTK::State&,
                                       const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                                       const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                       SimTK::Array_<SimTK::Real>& perr) const {
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const R& r = rows_[i];
    const Vec3 p_AS = findStationLocation(X_AB, r.F, r.p);
    const Vec3 p_BC = ~getBodyTransform(X_AB, r.B) * p_AS;
    perr[int(i)] = SimTK::dot(p_BC, r.n.asVec3()) - r.h;
  }
}

void ArmPlanesImpl::realizeTopology(SimTK::State& s) const {
  geoIndex_ = getMatterSubsystem().allocateCacheEntry(s, SimTK::Stage::Model, new SimTK::Value<GeoCache>());
}

const std::vector<ArmPlanesImpl::Geo>& ArmPlanesImpl::geometry(const SimTK::State& s) const {
  GeoCache& c = SimTK::Value<GeoCache>::updDowncast(getMatterSubsystem().updCacheEntry(s, geoIndex_)).upd();
  const SimTK::Vector& q = s.getQ();
  bool same = c.q.size() == q.size() && !c.rows.empty();
  for (int i = 0; same && i < q.size(); ++i) same = c.q[i] == q[i];
  if (same) return c.rows;
  c.rows.resize(rows_.size());
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const R& r = rows_[i];
    const SimTK::Transform& X_AF = getBodyTransformFromState(s, r.F);
    const SimTK::Transform& X_AB = getBodyTransformFromState(s, r.B);
    const Vec3 p_AS = X_AF * r.p;
    c.rows[i] = {X_AB.R() * r.n.asVec3(), p_AS - X_AF.p(), p_AS - X_AB.p()};
  }
  c.q = q;
  return c.rows;
}

void ArmPlanesImpl::calcPositionDotErrors(const SimTK::State& s,
                                          const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                          SimTK::Array_<SimTK::Real>& pverr) const {
  const std::vector<Geo>& g = geometry(s);
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const R& r = rows_[i];
    const SimTK::SpatialVec &VF = V_AB[r.F], &VB = V_AB[r.B];
    // v_CS = v_S(F) - v_C(B), the station velocities from each body's origin.
    const Vec3 v_CS = VF[1] + SimTK::cross(VF[0], g[i].rF) - VB[1] - SimTK::cross(VB[0], g[i].rB);
    pverr[int(i)] = SimTK::dot(v_CS, g[i].n);
  }
}

void ArmPlanesImpl::calcPositionDotDotErrors(const SimTK::State& s,
                                             const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                             SimTK::Array_<SimTK::Real>& paerr) const {
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const R& r = rows_[i];
    const Vec3 p_AS = findStationLocationFromState(s, r.F, r.p);
    const SimTK::Transform& X_AB = getBodyTransformFromState(s, r.B);
    const Vec3 p_BC = ~X_AB * p_AS;
    const Vec3 n_A = X_AB.R() * r.n.asVec3();
    const Vec3& w_AB = getBodyAngularVelocityFromState(s, r.B);
    const Vec3 v_CS = findStationVelocityFromState(s, r.F, r.p) - findStationVelocityFromState(s, r.B, p_BC);
    const Vec3 a_CS = findStationAcceleration(s, A_AB, r.F, r.p) - findStationAcceleration(s, A_AB, r.B, p_BC);
    paerr[int(i)] = SimTK::dot(a_CS - 2. * SimTK::cross(w_AB, v_CS), n_A);
  }
}

void ArmPlanesImpl::addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& lambda,
                                                  SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& F_A,
                                                  SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&) const {
  const std::vector<Geo>& g = geometry(s);
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    if (lambda[int(i)] == 0) continue;  // G^T column by column: most multipliers are zero
    const R& r = rows_[i];
    // lambda n at S on the knuckle, -lambda n at the coincident point C of the arm.
    const Vec3 f = lambda[int(i)] * g[i].n;
    F_A[r.F] += SimTK::SpatialVec(SimTK::cross(g[i].rF, f), f);
    F_A[r.B] -= SimTK::SpatialVec(SimTK::cross(g[i].rB, f), f);
  }
}

// ---------------------------------------------------------------------------
ReducedWishboneCorner buildReducedWishbone(Scene& scene, SimTK::MobilizedBody& chassis, const DoubleWishboneParams& p,
                                           const WishboneLoop& loop, const std::string& prefix) {
  ReducedWishboneCorner c;
  c.loop = &loop;
  buildWishboneCorner(scene, chassis, p, prefix, c, [&](ReducedWishboneCorner& k) {
    auto* impl = new ReducedKnuckleMobilizer(scene.updMatter(), loop);
    k.knuckle = SimTK::MobilizedBody::Custom(chassis, impl, makeRigidBody(p.knuckle));
    k.knuckle_mobilizer = impl;
    impl->setMobilizedBody(k.knuckle.getMobilizedBodyIndex());
  });
  return c;
}

void setReducedCornerPosition(SimTK::State& s, const ReducedWishboneCorner& c, double s_rad, double delta_rad) {
  c.knuckle.setOneQ(s, 0, s_rad);
  c.knuckle.setOneQ(s, 1, delta_rad);
  c.lower_arm.setOneQ(s, 0, s_rad);
  c.upper_arm.setOneQ(s, 0, c.loop->calcUpperArmAngle(s_rad)[0]);
  for (int i = 0; i < 2; ++i) c.knuckle.setOneU(s, i, 0);
  c.lower_arm.setOneU(s, 0, 0);
  c.upper_arm.setOneU(s, 0, 0);
}

}  // namespace vdyn
