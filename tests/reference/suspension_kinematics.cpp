// The suspension kinematics reference: each loop is a residual r(q) = 0 in the
// pose of one rigid body (upright or axle: rotation R, translation d, a body
// point at design position r_C is at R r_C + d) and the angles of its arms
// about their chassis axes; Newton's method with the analytic Jacobian, the
// rotation updated on the left, R <- exp([dphi]x) R. The driving inputs are
// raised in steps from the design pose (continuation) to stay on the branch.
#include "suspension_kinematics.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace vdyn::kinematics_reference {
namespace {

using Mat3 = std::array<Vec3, 3>;  // rows

Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 scale(double k, const Vec3& a) { return {k * a[0], k * a[1], k * a[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
Vec3 unit(const Vec3& a, const char* what) {
  const double n = norm(a);
  if (!(n > 1e-9)) throw std::invalid_argument(std::string("kinematics reference: ") + what + " has zero length");
  return scale(1.0 / n, a);
}
Vec3 mul(const Mat3& m, const Vec3& v) { return {dot(m[0], v), dot(m[1], v), dot(m[2], v)}; }
Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
  return c;
}
Mat3 identity() { return {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}}; }

// Rotation matrix of the rotation vector phi (Rodrigues).
Mat3 expRot(const Vec3& phi) {
  const double t = norm(phi);
  if (t == 0.0) return identity();
  const Vec3 a = scale(1.0 / t, phi);
  const double c = std::cos(t), s = std::sin(t), v = 1.0 - c;
  return {Vec3{c + a[0] * a[0] * v, a[0] * a[1] * v - a[2] * s, a[0] * a[2] * v + a[1] * s},
          Vec3{a[1] * a[0] * v + a[2] * s, c + a[1] * a[1] * v, a[1] * a[2] * v - a[0] * s},
          Vec3{a[2] * a[0] * v - a[1] * s, a[2] * a[1] * v + a[0] * s, c + a[2] * a[2] * v}};
}

// Vector v rotated by angle theta about the unit axis a.
Vec3 rotateAbout(const Vec3& a, double theta, const Vec3& v) {
  const double c = std::cos(theta), s = std::sin(theta);
  return add(add(scale(c, v), scale(s, cross(a, v))), scale(dot(a, v) * (1.0 - c), a));
}

struct State {
  Mat3 R = identity();  // body rotation from design
  Vec3 d{};             // body translation from design
  std::array<double, 2> theta{};  // arm angles about their chassis axes, rad
  Vec3 point(const Vec3& r_C) const { return add(mul(R, r_C), d); }
  Vec3 dir(const Vec3& u) const { return mul(R, u); }
};

// Unknowns: [dphi (3), dd (3), theta_0 .. theta_{arms-1}]; as many equations.
class Loop {
public:
  virtual ~Loop() = default;
  virtual int arms() const = 0;
  int size() const { return 6 + arms(); }
  virtual void residual(const State& s, double* r) const = 0;
  virtual void jacobian(const State& s, double* J) const = 0;  // row-major size x size
  // d(residual)/d(rack travel), for implicit differentiation (zero without a tie rod).
  virtual void residualRackDerivative(const State& /*s*/, double* dr) const {
    std::fill(dr, dr + size(), 0.0);
  }
  virtual void setInputs(double a, double b) = 0;
};

// Rows row0..row0+2, columns 0..5 of sign * d(body point)/d(dphi, dd), where
// v = R r_C: d point = dphi x v + dd.
void pointRows(double* J, int n, int row0, const Vec3& v, double sign) {
  const double m[3][3] = {{0, v[2], -v[1]}, {-v[2], 0, v[0]}, {v[1], -v[0], 0}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      J[(row0 + i) * n + j] = sign * m[i][j];
      J[(row0 + i) * n + 3 + j] = sign * (i == j ? 1.0 : 0.0);
    }
  }
}

// A revolute arm: pivot o on the chassis axis of unit direction a; its ball
// joint at design b0.
struct Arm {
  Vec3 o, a, b0;
  Vec3 ball(double theta) const { return add(o, rotateAbout(a, theta, sub(b0, o))); }
  Vec3 dball(double theta) const { return cross(a, sub(ball(theta), o)); }
};

Arm makeArm(const Vec3& front, const Vec3& back, const Vec3& ball, const char* what) {
  return Arm{front, unit(sub(front, back), what), ball};
}

// Ball joint: body point at r_C equals the arm's ball; rows row0..row0+2, arm column col.
void ballResidual(const State& s, const Arm& arm, int k, const Vec3& r_C, double* r) {
  const Vec3 e = sub(s.point(r_C), arm.ball(s.theta[k]));
  r[0] = e[0], r[1] = e[1], r[2] = e[2];
}
void ballJacobian(const State& s, const Arm& arm, int k, const Vec3& r_C, double* J, int n, int row0) {
  pointRows(J, n, row0, s.dir(r_C), 1.0);
  const Vec3 db = arm.dball(s.theta[k]);
  for (int i = 0; i < 3; ++i) J[(row0 + i) * n + 6 + k] = -db[i];
}

// Distance link of design length L from fixed point c to body point r_C, as
// (|p - c|^2 - L^2) / (2 L) (metres, ~ the length error).
struct Link {
  Vec3 c, r_C;
  double L;
};
Link makeLink(const Vec3& c, const Vec3& r_C, const char* what) {
  const double L = norm(sub(r_C, c));
  if (!(L > 1e-9)) throw std::invalid_argument(std::string("kinematics reference: ") + what + " has zero length");
  return Link{c, r_C, L};
}
double linkResidual(const State& s, const Link& l, const Vec3& shift) {
  const Vec3 u = sub(s.point(l.r_C), add(l.c, shift));
  return (dot(u, u) - l.L * l.L) / (2.0 * l.L);
}
void linkJacobian(const State& s, const Link& l, const Vec3& shift, double* J, int n, int row) {
  const Vec3 u = sub(s.point(l.r_C), add(l.c, shift));
  const Vec3 g = scale(1.0 / l.L, cross(s.dir(l.r_C), u));
  for (int j = 0; j < 3; ++j) {
    J[row * n + j] = g[j];
    J[row * n + 3 + j] = u[j] / l.L;
  }
}

// Vertical position of body point r_C: p_z - target.
void heightJacobian(const State& s, const Vec3& r_C, double* J, int n, int row) {
  const Vec3 v = s.dir(r_C);
  J[row * n + 0] = v[1], J[row * n + 1] = -v[0], J[row * n + 2] = 0.0;
  J[row * n + 3] = 0.0, J[row * n + 4] = 0.0, J[row * n + 5] = 1.0;
}

double sideOf(const Vec3& spindle) {
  if (spindle[1] == 0.0)
    throw std::invalid_argument("kinematics reference: the wheel centre lies on y = 0; its side is undefined");
  return spindle[1] < 0.0 ? -1.0 : 1.0;
}

class MacPhersonLoop : public Loop {
public:
  explicit MacPhersonLoop(const MacPhersonHardpoints& hp)
      : hp_(hp), lca_(makeArm(hp.lca_f, hp.lca_b, hp.lca_u, "the LCA axis LCA_F-LCA_B")),
        tierod_(makeLink(hp.tierod_c, hp.tierod_u, "the tie rod TIEROD_C-TIEROD_U")) {
    const Vec3 w = unit(sub(hp.strut_c, hp.strut_u), "the strut STRUT_U-STRUT_C");
    // Two unit normals to the strut axis, fixed in the upright.
    const Vec3 seed = std::fabs(w[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    n1_ = unit(cross(w, seed), "strut normal");
    n2_ = cross(w, n1_);
  }
  int arms() const override { return 1; }
  void setInputs(double z, double rack) override { z_ = z, rack_ = rack; }
  void residual(const State& s, double* r) const override {
    ballResidual(s, lca_, 0, hp_.lca_u, r);
    const Vec3 e = sub(hp_.strut_c, s.point(hp_.strut_u));
    r[3] = dot(s.dir(n1_), e);
    r[4] = dot(s.dir(n2_), e);
    r[5] = linkResidual(s, tierod_, {0, rack_, 0});
    r[6] = s.point(hp_.spindle)[2] - (hp_.spindle[2] + z_);
  }
  void jacobian(const State& s, double* J) const override {
    const int n = size();
    std::fill(J, J + n * n, 0.0);
    ballJacobian(s, lca_, 0, hp_.lca_u, J, n, 0);
    const Vec3 v = s.dir(hp_.strut_u);
    const Vec3 e = sub(hp_.strut_c, s.point(hp_.strut_u));
    int row = 3;
    for (const Vec3* n0 : {&n1_, &n2_}) {
      const Vec3 nv = s.dir(*n0);
      const Vec3 g = cross(nv, add(e, v));
      for (int j = 0; j < 3; ++j) J[row * n + j] = g[j], J[row * n + 3 + j] = -nv[j];
      ++row;
    }
    linkJacobian(s, tierod_, {0, rack_, 0}, J, n, 5);
    heightJacobian(s, hp_.spindle, J, n, 6);
  }
  void residualRackDerivative(const State& s, double* dr) const override {
    std::fill(dr, dr + size(), 0.0);
    const Vec3 u = sub(s.point(tierod_.r_C), add(tierod_.c, {0, rack_, 0}));
    dr[5] = -u[1] / tierod_.L;
  }

private:
  MacPhersonHardpoints hp_;
  Arm lca_;
  Link tierod_;
  Vec3 n1_{}, n2_{};
  double z_ = 0.0, rack_ = 0.0;
};

// With knuckle steering (vdyn's (A.1)) the tie-rod row is x . s_left + sin(steer)
// = 0 and the second input is the steer angle.
class DoubleWishboneLoop : public Loop {
public:
  DoubleWishboneLoop(const DoubleWishboneHardpoints& hp, bool knuckle_steer)
      : hp_(hp), knuckle_(knuckle_steer),
        lca_(makeArm(hp.lca_f, hp.lca_b, hp.lca_u, "the LCA axis LCA_F-LCA_B")),
        uca_(makeArm(hp.uca_f, hp.uca_b, hp.uca_u, "the UCA axis UCA_F-UCA_B")),
        tierod_(knuckle_steer ? Link{{0, 0, 0}, {0, 0, 0}, 1.0}
                              : makeLink(hp.tierod_c, hp.tierod_u, "the tie rod TIEROD_C-TIEROD_U")) {
    const double side = sideOf(hp.spindle);
    spin_left_ = scale(side, spinAxisOutward(hp.camber_rad, hp.toe_in_rad, side));
  }
  explicit DoubleWishboneLoop(const DoubleWishboneHardpoints& hp) : DoubleWishboneLoop(hp, false) {}
  int arms() const override { return 2; }
  void setInputs(double z, double second) override { z_ = z, second_ = second; }
  void residual(const State& s, double* r) const override {
    ballResidual(s, lca_, 0, hp_.lca_u, r);
    ballResidual(s, uca_, 1, hp_.uca_u, r + 3);
    r[6] = knuckle_ ? s.dir(spin_left_)[0] + std::sin(second_) : linkResidual(s, tierod_, {0, second_, 0});
    r[7] = s.point(hp_.spindle)[2] - (hp_.spindle[2] + z_);
  }
  void jacobian(const State& s, double* J) const override {
    const int n = size();
    std::fill(J, J + n * n, 0.0);
    ballJacobian(s, lca_, 0, hp_.lca_u, J, n, 0);
    ballJacobian(s, uca_, 1, hp_.uca_u, J, n, 3);
    if (knuckle_) {
      const Vec3 a = s.dir(spin_left_);  // d(x . a) = dphi . (a x x_hat)
      J[6 * n + 0] = 0.0, J[6 * n + 1] = a[2], J[6 * n + 2] = -a[1];
    } else {
      linkJacobian(s, tierod_, {0, second_, 0}, J, n, 6);
    }
    heightJacobian(s, hp_.spindle, J, n, 7);
  }
  void residualRackDerivative(const State& s, double* dr) const override {
    std::fill(dr, dr + size(), 0.0);
    if (knuckle_) return;
    const Vec3 u = sub(s.point(tierod_.r_C), add(tierod_.c, {0, second_, 0}));
    dr[6] = -u[1] / tierod_.L;
  }

private:
  DoubleWishboneHardpoints hp_;
  bool knuckle_;
  Arm lca_, uca_;
  Link tierod_;
  Vec3 spin_left_{};
  double z_ = 0.0, second_ = 0.0;
};

struct KnuckleSteeredWishbone : DoubleWishboneLoop {
  explicit KnuckleSteeredWishbone(const DoubleWishboneHardpoints& hp) : DoubleWishboneLoop(hp, true) {}
};

class SolidAxleLoop : public Loop {
public:
  explicit SolidAxleLoop(const SolidAxleHardpoints& hp) : hp_(hp) {
    if (hp.links.size() != 4) {
      std::ostringstream m;
      m << "kinematics reference: a solid axle needs exactly 4 links (2 degrees of freedom), got "
        << hp.links.size();
      throw std::invalid_argument(m.str());
    }
    if (!(hp.spindle_right[1] < 0.0 && hp.spindle_left[1] > 0.0))
      throw std::invalid_argument("kinematics reference: solid axle: spindle_right needs y < 0, spindle_left y > 0");
    for (const AxleLink& l : hp.links) links_.push_back(makeLink(l.chassis, l.axle, l.name.c_str()));
  }
  int arms() const override { return 0; }
  void setInputs(double zr, double zl) override { zr_ = zr, zl_ = zl; }
  void residual(const State& s, double* r) const override {
    for (int i = 0; i < 4; ++i) r[i] = linkResidual(s, links_[i], {0, 0, 0});
    r[4] = s.point(hp_.spindle_right)[2] - (hp_.spindle_right[2] + zr_);
    r[5] = s.point(hp_.spindle_left)[2] - (hp_.spindle_left[2] + zl_);
  }
  void jacobian(const State& s, double* J) const override {
    const int n = size();
    std::fill(J, J + n * n, 0.0);
    for (int i = 0; i < 4; ++i) linkJacobian(s, links_[i], {0, 0, 0}, J, n, i);
    heightJacobian(s, hp_.spindle_right, J, n, 4);
    heightJacobian(s, hp_.spindle_left, J, n, 5);
  }

private:
  SolidAxleHardpoints hp_;
  std::vector<Link> links_;
  double zr_ = 0.0, zl_ = 0.0;
};

// Solves A x = b in place (Gaussian elimination, partial pivoting); n <= 8.
void solveDense(std::vector<double> A, std::vector<double>& b, int n) {
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (std::fabs(A[i * n + k]) > std::fabs(A[p * n + k])) p = i;
    if (!(std::fabs(A[p * n + k]) > 1e-14))
      throw std::runtime_error("kinematics reference: the loop Jacobian is singular (a locked or "
                               "undetermined mechanism at this pose)");
    if (p != k) {
      for (int j = 0; j < n; ++j) std::swap(A[k * n + j], A[p * n + j]);
      std::swap(b[k], b[p]);
    }
    for (int i = k + 1; i < n; ++i) {
      const double f = A[i * n + k] / A[k * n + k];
      for (int j = k; j < n; ++j) A[i * n + j] -= f * A[k * n + j];
      b[i] -= f * b[k];
    }
  }
  for (int k = n - 1; k >= 0; --k) {
    double s = b[k];
    for (int j = k + 1; j < n; ++j) s -= A[k * n + j] * b[j];
    b[k] = s / A[k * n + k];
  }
}

void applyStep(State& s, const std::vector<double>& dx, int arms) {
  s.R = mul(expRot({dx[0], dx[1], dx[2]}), s.R);
  s.d = add(s.d, {dx[3], dx[4], dx[5]});
  for (int k = 0; k < arms; ++k) s.theta[k] += dx[6 + k];
}

double maxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

constexpr double kResidualTolerance = 1e-13;  // m
constexpr double kResidualLimit = 1e-12;      // m: a solution worse than this is an error

// Newton's method from s; returns the iterations taken.
int newton(const Loop& loop, State& s) {
  const int n = loop.size();
  std::vector<double> r(n), J(n * n);
  for (int it = 0; it < 60; ++it) {
    loop.residual(s, r.data());
    const double res = maxAbs(r);
    if (res < kResidualTolerance) return it;
    loop.jacobian(s, J.data());
    for (double& x : r) x = -x;
    solveDense(J, r, n);
    applyStep(s, r, loop.arms());
    if (maxAbs(r) < 1e-15 && res < kResidualLimit) return it + 1;
  }
  loop.residual(s, r.data());
  if (maxAbs(r) < kResidualLimit) return 60;
  std::ostringstream m;
  m << "kinematics reference: Newton did not close the loop in 60 iterations (residual " << maxAbs(r)
    << " m)";
  throw std::runtime_error(m.str());
}

// Raises the inputs (a, b) from zero in steps of at most 20 mm / 10 mm.
State solve(Loop& loop, double a, double b, double step_a, double step_b, int& iterations) {
  const int steps = std::max({1, static_cast<int>(std::ceil(std::fabs(a) / step_a)),
                              static_cast<int>(std::ceil(std::fabs(b) / step_b))});
  State s;
  iterations = 0;
  for (int k = 1; k <= steps; ++k) {
    const double f = static_cast<double>(k) / steps;
    loop.setInputs(f * a, f * b);
    iterations += newton(loop, s);
  }
  return s;
}

double loopResidual(const Loop& loop, const State& s) {
  std::vector<double> r(loop.size());
  loop.residual(s, r.data());
  return maxAbs(r);
}

WheelKinematics wheelOutputs(const State& s, const Vec3& spindle, const Vec3& spin_out0) {
  const double side = sideOf(spindle);
  WheelKinematics w;
  w.wheel_centre_m = s.point(spindle);
  w.spin_axis_out = s.dir(spin_out0);
  const Vec3& so = w.spin_axis_out;
  w.camber_rad = std::asin(std::clamp(-so[2], -1.0, 1.0));
  w.toe_in_rad = std::atan2(so[0], side * so[1]);
  const Vec3 sl = scale(side, so);  // pointing left
  w.steer_rad = std::atan2(-sl[0], sl[1]);
  w.track_change_m = side * (w.wheel_centre_m[1] - spindle[1]);
  w.dx_m = w.wheel_centre_m[0] - spindle[0];
  w.dz_m = w.wheel_centre_m[2] - spindle[2];
  return w;
}

// d(steer)/d(rack) by implicit differentiation: J dq = -dr/ds, then
// d steer = grad(steer) . dphi with grad = (-sx sz, -sy sz, sx^2 + sy^2) / (sx^2 + sy^2).
double steerRackDerivative(const Loop& loop, const State& s, const Vec3& spin_axis) {
  const int n = loop.size();
  std::vector<double> J(n * n), dr(n);
  loop.jacobian(s, J.data());
  loop.residualRackDerivative(s, dr.data());
  for (double& x : dr) x = -x;
  solveDense(J, dr, n);
  const Vec3& a = spin_axis;
  const double h = a[0] * a[0] + a[1] * a[1];
  return (-a[0] * a[2] * dr[0] - a[1] * a[2] * dr[1] + h * dr[2]) / h;
}

template <class Hp, class L>
WheelKinematics cornerKinematics(const Hp& hp, double z, double rack) {
  if (!std::isfinite(z) || !std::isfinite(rack))
    throw std::invalid_argument("kinematics reference: wheel and rack travel must be finite");
  L loop(hp);
  int it = 0;
  const State s = solve(loop, z, rack, 0.02, 0.01, it);
  WheelKinematics w = wheelOutputs(s, hp.spindle, spinAxisOutward(hp.camber_rad, hp.toe_in_rad, sideOf(hp.spindle)));
  w.loop_residual = loopResidual(loop, s);
  w.newton_iterations = it;
  w.dsteer_drack_rad_per_m = steerRackDerivative(loop, s, w.spin_axis_out);
  return w;
}

double jacobianError(Loop& loop, double a, double b, double h) {
  int it = 0;
  const State s = solve(loop, a, b, 0.02, 0.01, it);
  const int n = loop.size();
  std::vector<double> J(n * n), rp(n), rm(n), dx(n);
  loop.jacobian(s, J.data());
  double err = 0.0;
  for (int j = 0; j < n; ++j) {
    State sp = s, sm = s;
    std::fill(dx.begin(), dx.end(), 0.0);
    dx[j] = h;
    applyStep(sp, dx, loop.arms());
    dx[j] = -h;
    applyStep(sm, dx, loop.arms());
    loop.residual(sp, rp.data());
    loop.residual(sm, rm.data());
    for (int i = 0; i < n; ++i) err = std::max(err, std::fabs((rp[i] - rm[i]) / (2.0 * h) - J[i * n + j]));
  }
  return err;
}

Vec3 mirror(const Vec3& p) { return {p[0], -p[1], p[2]}; }

template <class Hp, class L>
RackSteer rackSteerOf(const Hp& right, double pinion, double c, double z) {
  if (!(c != 0.0) || !std::isfinite(c))
    throw std::invalid_argument("kinematics reference: rack c-factor must be finite and non-zero (m/rad)");
  if (sideOf(right.spindle) > 0.0)
    throw std::invalid_argument("kinematics reference: rackSteer takes the right corner (wheel centre y < 0)");
  RackSteer out;
  out.rack_travel_m = c * pinion;
  out.right = cornerKinematics<Hp, L>(right, z, out.rack_travel_m);
  out.left = cornerKinematics<Hp, L>(mirrored(right), z, out.rack_travel_m);
  out.steer_right_rad = out.right.steer_rad;
  out.steer_left_rad = out.left.steer_rad;
  out.steer_mean_rad = 0.5 * (out.steer_right_rad + out.steer_left_rad);
  const double dmean = 0.5 * (out.right.dsteer_drack_rad_per_m + out.left.dsteer_drack_rad_per_m);
  out.overall_ratio = 1.0 / (c * dmean);
  return out;
}

}  // namespace

Vec3 spinAxisOutward(double camber_rad, double toe_in_rad, double y_sign) {
  const double side = y_sign < 0.0 ? -1.0 : 1.0;
  return {std::cos(camber_rad) * std::sin(toe_in_rad), side * std::cos(camber_rad) * std::cos(toe_in_rad),
          -std::sin(camber_rad)};
}

WheelKinematics macphersonKinematics(const MacPhersonHardpoints& hp, double wheel_travel_m, double rack_travel_m) {
  return cornerKinematics<MacPhersonHardpoints, MacPhersonLoop>(hp, wheel_travel_m, rack_travel_m);
}

WheelKinematics doubleWishboneKinematics(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                         double rack_travel_m) {
  return cornerKinematics<DoubleWishboneHardpoints, DoubleWishboneLoop>(hp, wheel_travel_m, rack_travel_m);
}

AxleKinematics solidAxleKinematics(const SolidAxleHardpoints& hp, double travel_right_m, double travel_left_m) {
  if (!std::isfinite(travel_right_m) || !std::isfinite(travel_left_m))
    throw std::invalid_argument("kinematics reference: wheel travel must be finite");
  SolidAxleLoop loop(hp);
  int it = 0;
  const State s = solve(loop, travel_right_m, travel_left_m, 0.02, 0.02, it);
  AxleKinematics out;
  out.right = wheelOutputs(s, hp.spindle_right, spinAxisOutward(hp.camber_rad, hp.toe_in_rad, -1.0));
  out.left = wheelOutputs(s, hp.spindle_left, spinAxisOutward(hp.camber_rad, hp.toe_in_rad, 1.0));
  out.right.loop_residual = out.left.loop_residual = loopResidual(loop, s);
  out.right.newton_iterations = out.left.newton_iterations = it;
  const Vec3 c = sub(out.left.wheel_centre_m, out.right.wheel_centre_m);
  out.roll_rad = std::asin(std::clamp(c[2] / norm(c), -1.0, 1.0));
  return out;
}

MacPhersonHardpoints mirrored(const MacPhersonHardpoints& hp) {
  MacPhersonHardpoints m = hp;
  for (Vec3* p : {&m.spindle, &m.lca_f, &m.lca_b, &m.lca_u, &m.strut_c, &m.strut_u, &m.tierod_c, &m.tierod_u})
    *p = mirror(*p);
  return m;
}

DoubleWishboneHardpoints mirrored(const DoubleWishboneHardpoints& hp) {
  DoubleWishboneHardpoints m = hp;
  for (Vec3* p : {&m.spindle, &m.uca_f, &m.uca_b, &m.uca_u, &m.lca_f, &m.lca_b, &m.lca_u, &m.tierod_c, &m.tierod_u})
    *p = mirror(*p);
  return m;
}

RackSteer rackSteer(const MacPhersonHardpoints& right, double pinion_rad, double c_m_per_rad, double wheel_travel_m) {
  return rackSteerOf<MacPhersonHardpoints, MacPhersonLoop>(right, pinion_rad, c_m_per_rad, wheel_travel_m);
}

RackSteer rackSteer(const DoubleWishboneHardpoints& right, double pinion_rad, double c_m_per_rad,
                    double wheel_travel_m) {
  return rackSteerOf<DoubleWishboneHardpoints, DoubleWishboneLoop>(right, pinion_rad, c_m_per_rad, wheel_travel_m);
}

WheelKinematics doubleWishboneKinematicsKnuckleSteer(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                                     double steer_rad) {
  WheelKinematics w = cornerKinematics<DoubleWishboneHardpoints, KnuckleSteeredWishbone>(hp, wheel_travel_m, steer_rad);
  w.dsteer_drack_rad_per_m = 0.0;
  return w;
}

double doubleWishboneKnuckleSteerJacobianError(const DoubleWishboneHardpoints& hp, double wheel_travel_m,
                                               double steer_rad, double h) {
  KnuckleSteeredWishbone loop(hp);
  return jacobianError(loop, wheel_travel_m, steer_rad, h);
}

double macphersonJacobianError(const MacPhersonHardpoints& hp, double wheel_travel_m, double rack_travel_m, double h) {
  MacPhersonLoop loop(hp);
  return jacobianError(loop, wheel_travel_m, rack_travel_m, h);
}

double doubleWishboneJacobianError(const DoubleWishboneHardpoints& hp, double wheel_travel_m, double rack_travel_m,
                                   double h) {
  DoubleWishboneLoop loop(hp);
  return jacobianError(loop, wheel_travel_m, rack_travel_m, h);
}

double solidAxleJacobianError(const SolidAxleHardpoints& hp, double travel_right_m, double travel_left_m, double h) {
  SolidAxleLoop loop(hp);
  return jacobianError(loop, travel_right_m, travel_left_m, h);
}

}  // namespace vdyn::kinematics_reference
