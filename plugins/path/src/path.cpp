#include "vdyn/path/path.h"

#include <cmath>

namespace vdyn {

using SimTK::Vec2;

namespace {
double cross2(const Vec2& a, const Vec2& b) { return a[0] * b[1] - a[1] * b[0]; }
void requireFiniteVec(const Vec2& v, const std::string& what) {
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]))
    throw Error("path: " + what + " must be finite, got (" + formatValue(v[0]) + ", " + formatValue(v[1]) + ")");
}
}  // namespace

double wrapAngle(double a) {
  a = std::remainder(a, 2 * SimTK::Pi);  // [-pi, pi]
  return a <= -SimTK::Pi ? a + 2 * SimTK::Pi : a;
}

// ---------------------------------------------------------------------------
PathPoint ReferencePath::calcReferencePoint(const Vec2& p_G) const {
  requireFiniteVec(p_G, "position");
  return DoCalcReferencePoint(p_G);
}

PathErrors ReferencePath::calcErrors(const Vec2& p_G, const Vec2& v_G) const {
  requireFiniteVec(p_G, "position");
  requireFiniteVec(v_G, "velocity");
  return DoCalcErrors(p_G, v_G);
}

double ReferencePath::calcDistance(const Vec2& p_G) const {
  requireFiniteVec(p_G, "position");
  return DoCalcDistance(p_G);
}

std::vector<PathPoint> ReferencePath::sample(double lead_in_m, double lead_out_m, double spacing_m) const {
  requireNonNegative(lead_in_m, "path sample lead_in_m");
  requireNonNegative(lead_out_m, "path sample lead_out_m");
  requirePositive(spacing_m, "path sample spacing_m");
  return DoSample(lead_in_m, lead_out_m, spacing_m);
}

// ---------------------------------------------------------------------------
void LaneChangeParams::validate() const {
  requireFinite(start_x_m, "lane change start_x_m");
  requireFinite(start_y_m, "lane change start_y_m");
  requirePositive(length_m, "lane change length_m");
  requireFinite(shift_m, "lane change shift_m");
}

LaneChangeParams LaneChangeParams::fromParams(const ParamReader& r) {
  LaneChangeParams p;
  p.start_x_m = r.numberOr("start_x_m", p.start_x_m);
  p.start_y_m = r.numberOr("start_y_m", p.start_y_m);
  p.length_m = r.number("length_m");
  p.shift_m = r.number("shift_m");
  p.validate();
  return p;
}

LaneChangePath::LaneChangePath(const LaneChangeParams& p) : p_(p) {
  p_.validate();
  h_ = p_.length_m / 2;
}

// (7.7): the first half rises by D/2 with zero slope and curvature at X0; the
// second half is its point mirror about the midpoint.
double LaneChangePath::calcY(double X) const {
  const double D = p_.shift_m, X0 = p_.start_x_m, Xf = X0 + p_.length_m;
  if (X <= X0) return p_.start_y_m;
  if (X >= Xf) return p_.start_y_m + D;
  if (X <= X0 + h_) {
    const double u = (X - X0) / h_;
    return p_.start_y_m + D * u * u * u * (1 - u / 2);  // (7.7a)
  }
  const double u = (Xf - X) / h_;
  return p_.start_y_m + D - D * u * u * u * (1 - u / 2);  // (7.7b)
}

double LaneChangePath::calcSlope(double X) const {
  const double D = p_.shift_m, X0 = p_.start_x_m, Xf = X0 + p_.length_m;
  if (X <= X0 || X >= Xf) return 0;
  // (7.8): D/h (3 u^2 - 2 u^3) on both halves (u' on the second).
  const double u = X <= X0 + h_ ? (X - X0) / h_ : (Xf - X) / h_;
  return D / h_ * u * u * (3 - 2 * u);
}

double LaneChangePath::calcSecondDerivative(double X) const {
  const double D = p_.shift_m, X0 = p_.start_x_m, Xf = X0 + p_.length_m;
  if (X <= X0 || X >= Xf) return 0;
  if (X <= X0 + h_) {
    const double u = (X - X0) / h_;
    return D / (h_ * h_) * 6 * u * (1 - u);
  }
  const double u = (Xf - X) / h_;
  return -D / (h_ * h_) * 6 * u * (1 - u);
}

PathPoint LaneChangePath::DoCalcReferencePoint(const Vec2& p) const {
  const double X = p[0], s = calcSlope(X);
  return {Vec2(X, calcY(X)), std::atan(s), calcSecondDerivative(X) / std::pow(1 + s * s, 1.5)};
}

namespace {
// Paths that are graphs Y(X) (lane changes): the errors (7.9)-(7.10) and the
// closest-point distance from Y, Y' and Y''.
template <class G>
PathErrors graphErrors(const G& g, const char* what, const Vec2& p, const Vec2& v) {
  // The slope y'/x' (7.10) needs motion along +X.
  if (!(v[0] > 1e-3))
    throw Error(std::string(what) + ": the vehicle must move along +X for the slope error (7.10), got x' = " +
                formatValue(v[0]) + " m/s");
  return {p[1] - g.calcY(p[0]),                 // (7.9)
          v[1] / v[0] - g.calcSlope(p[0])};     // (7.10)
}

template <class G>
double graphDistance(const G& g, const Vec2& p) {
  // Closest point: Newton on g(X) = (X - px) + (Y(X) - py) Y'(X) = 0 from X = px.
  double X = p[0];
  for (int i = 0; i < 50; ++i) {
    const double Y = g.calcY(X), s = g.calcSlope(X), k = g.calcSecondDerivative(X);
    const double r = (X - p[0]) + (Y - p[1]) * s, dr = 1 + s * s + (Y - p[1]) * k;
    const double dX = -r / (dr > 0.1 ? dr : 0.1);
    X += dX;
    if (std::abs(dX) < 1e-13 * std::max(1.0, std::abs(X))) break;
  }
  const double s = g.calcSlope(X);
  const Vec2 t = Vec2(1, s) / std::sqrt(1 + s * s);
  const Vec2 d = p - Vec2(X, g.calcY(X));
  const double dist = d.norm();
  return cross2(t, d) >= 0 ? dist : -dist;
}

template <class G>
PathPoint graphPoint(const G& g, double X) {
  const double s = g.calcSlope(X);
  return {Vec2(X, g.calcY(X)), std::atan(s), g.calcSecondDerivative(X) / std::pow(1 + s * s, 1.5)};
}
}  // namespace

PathErrors LaneChangePath::DoCalcErrors(const Vec2& p, const Vec2& v) const {
  return graphErrors(*this, "lane change path", p, v);
}

double LaneChangePath::DoCalcDistance(const Vec2& p) const { return graphDistance(*this, p); }

// ---------------------------------------------------------------------------
void DoubleLaneChangeParams::validate() const {
  requireFinite(start_y_m, "double lane change start_y_m");
  first.validate();
  second.validate();
  if (second.start_x_m < first.start_x_m + first.length_m)
    throw Error("double lane change: the second lane change (start_x_m " + formatValue(second.start_x_m) +
                " m) must start where or after the first ends (" + formatValue(first.start_x_m + first.length_m) +
                " m)");
}

DoubleLaneChangeParams DoubleLaneChangeParams::fromParams(const ParamReader& r) {
  DoubleLaneChangeParams p;
  p.start_y_m = r.numberOr("start_y_m", p.start_y_m);
  for (auto [key, lc] : {std::pair<const char*, LaneChangeParams*>{"first", &p.first}, {"second", &p.second}}) {
    const ParamReader c = r.child(key);
    lc->start_x_m = c.number("start_x_m");
    lc->length_m = c.number("length_m");
    lc->shift_m = c.number("shift_m");
  }
  p.validate();
  return p;
}

DoubleLaneChangePath::DoubleLaneChangePath(const DoubleLaneChangeParams& p) : p_(p) {
  p_.validate();
  p_.first.start_y_m = p_.start_y_m;
  p_.second.start_y_m = 0;  // b_ adds its rise to a_'s
  a_ = std::make_unique<LaneChangePath>(p_.first);
  b_ = std::make_unique<LaneChangePath>(p_.second);
  p_.second.start_y_m = p_.start_y_m + p_.first.shift_m;
}

double DoubleLaneChangePath::calcY(double X) const { return a_->calcY(X) + b_->calcY(X); }
double DoubleLaneChangePath::calcSlope(double X) const { return a_->calcSlope(X) + b_->calcSlope(X); }
double DoubleLaneChangePath::calcSecondDerivative(double X) const {
  return a_->calcSecondDerivative(X) + b_->calcSecondDerivative(X);
}
PathPoint DoubleLaneChangePath::DoCalcReferencePoint(const Vec2& p) const { return graphPoint(*this, p[0]); }
PathErrors DoubleLaneChangePath::DoCalcErrors(const Vec2& p, const Vec2& v) const {
  return graphErrors(*this, "double lane change path", p, v);
}
double DoubleLaneChangePath::DoCalcDistance(const Vec2& p) const { return graphDistance(*this, p); }
std::vector<PathPoint> DoubleLaneChangePath::DoSample(double in, double out, double spacing) const {
  std::vector<PathPoint> pts;
  const double a = p_.first.start_x_m - in, b = p_.second.start_x_m + p_.second.length_m + out;
  const int n = std::max(1, static_cast<int>(std::ceil((b - a) / spacing)));
  for (int i = 0; i <= n; ++i) pts.push_back(graphPoint(*this, a + (b - a) * i / n));
  return pts;
}

std::vector<PathPoint> LaneChangePath::DoSample(double in, double out, double spacing) const {
  std::vector<PathPoint> pts;
  const double a = p_.start_x_m - in, b = p_.start_x_m + p_.length_m + out;
  const int n = std::max(1, static_cast<int>(std::ceil((b - a) / spacing)));
  for (int i = 0; i <= n; ++i) {
    const double X = a + (b - a) * i / n;
    pts.push_back(DoCalcReferencePoint(Vec2(X, 0)));
  }
  return pts;
}

// ---------------------------------------------------------------------------
void JTurnParams::validate() const {
  requireFinite(start_x_m, "j-turn start_x_m");
  requireFinite(start_y_m, "j-turn start_y_m");
  requireFinite(start_heading_rad, "j-turn start_heading_rad");
  requireNonNegative(entry_length_m, "j-turn entry_length_m");
  requirePositive(radius_m, "j-turn radius_m");
  if (!(exit_angle_rad > 0 && exit_angle_rad <= SimTK::Pi))
    throw Error("j-turn exit angle must be in (0, 180] deg, got " + formatValue(exit_angle_rad * 180 / SimTK::Pi) +
                " deg");
}

JTurnParams JTurnParams::fromParams(const ParamReader& r) {
  JTurnParams p;
  p.start_x_m = r.numberOr("start_x_m", p.start_x_m);
  p.start_y_m = r.numberOr("start_y_m", p.start_y_m);
  p.start_heading_rad = r.numberOr("start_heading_rad", p.start_heading_rad);
  p.entry_length_m = r.number("entry_length_m");
  p.radius_m = r.number("radius_m");
  p.exit_angle_rad = r.number("exit_angle_deg") * SimTK::Pi / 180;
  const std::string turn = r.stringOr("turn", "left");
  if (turn != "left" && turn != "right")
    throw Error(r.at("turn") + ": must be \"left\" or \"right\", got \"" + turn + "\"");
  p.turn_left = turn == "left";
  p.validate();
  return p;
}

JTurnPath::JTurnPath(const JTurnParams& p) : p_(p) {
  p_.validate();
  sign_ = p_.turn_left ? 1.0 : -1.0;
  const double psi0 = p_.start_heading_rad, psiF = psi0 + sign_ * p_.exit_angle_rad;
  t0_ = Vec2(std::cos(psi0), std::sin(psi0));
  const Vec2 n0 = sign_ * Vec2(-std::sin(psi0), std::cos(psi0));  // towards the centre
  entry_ = Vec2(p_.start_x_m, p_.start_y_m) + p_.entry_length_m * t0_;
  c_ = entry_ + p_.radius_m * n0;
  tF_ = Vec2(std::cos(psiF), std::sin(psiF));
  exit_ = c_ - p_.radius_m * sign_ * Vec2(-std::sin(psiF), std::cos(psiF));
}

PathPoint JTurnPath::calcPointAtArcLength(double s) const {
  const double Le = p_.entry_length_m, R = p_.radius_m, psi0 = p_.start_heading_rad;
  if (s <= Le) return {Vec2(p_.start_x_m, p_.start_y_m) + s * t0_, psi0, 0.0};
  const double sExit = arcLengthToExit();
  if (s >= sExit) return {exit_ + (s - sExit) * tF_, psi0 + sign_ * p_.exit_angle_rad, 0.0};
  const double psi = psi0 + sign_ * (s - Le) / R;
  return {c_ - R * sign_ * Vec2(-std::sin(psi), std::cos(psi)), psi, sign_ / R};
}

// The closest of the three pieces: entry line (ending at the entry point),
// arc, exit line (starting at the exit point). On the arc the closest point is
// the radial projection of (7.19); its tangent direction is (7.23).
JTurnPath::Part JTurnPath::partOf(const Vec2& p) const {
  const Vec2 dE = p - entry_, dX = p - exit_;
  const double sE = SimTK::dot(dE, t0_), sX = SimTK::dot(dX, tF_);
  const double distEntry = sE <= 0 ? std::abs(cross2(t0_, dE)) : dE.norm();
  const double distExit = sX >= 0 ? std::abs(cross2(tF_, dX)) : dX.norm();
  const Vec2 r = p - c_;
  const double thetaE = std::atan2(entry_[1] - c_[1], entry_[0] - c_[0]);
  const double phi = sign_ * wrapAngle(std::atan2(r[1], r[0]) - thetaE);  // angle travelled on the circle
  const double distArc = (phi >= 0 && phi <= p_.exit_angle_rad) ? std::abs(r.norm() - p_.radius_m)
                                                                  : std::min(dE.norm(), dX.norm());
  if (distArc <= distEntry && distArc <= distExit) return Part::Circle;
  return distEntry <= distExit ? Part::Entry : Part::Exit;
}

PathPoint JTurnPath::DoCalcReferencePoint(const Vec2& p) const {
  const double psi0 = p_.start_heading_rad;
  switch (partOf(p)) {
    case Part::Entry: return {entry_ + SimTK::dot(p - entry_, t0_) * t0_, psi0, 0.0};
    case Part::Exit: return {exit_ + SimTK::dot(p - exit_, tF_) * tF_, psi0 + sign_ * p_.exit_angle_rad, 0.0};
    case Part::Circle: break;
  }
  const Vec2 r = p - c_;
  const double thetaE = std::atan2(entry_[1] - c_[1], entry_[0] - c_[0]);
  const double phi = sign_ * wrapAngle(std::atan2(r[1], r[0]) - thetaE);
  const double n = r.norm();
  const Vec2 foot = n > 0 ? c_ + p_.radius_m / n * r : entry_;
  return {foot, psi0 + sign_ * phi, sign_ / p_.radius_m};
}

PathErrors JTurnPath::DoCalcErrors(const Vec2& p, const Vec2& v) const {
  const PathPoint ref = DoCalcReferencePoint(p);
  // e1: |p - c| - R (7.19), signed + left of the path (inside a left turn);
  // on the lines the signed perpendicular offset. e2: direction of travel
  // atan2(y', x') (7.24) minus the tangent direction (7.23), wrapped (7.21).
  const double e1 = cross2(ref.tangent(), p - ref.p_G);
  const double e2 = wrapAngle(std::atan2(v[1], v[0]) - ref.heading_rad);
  return {e1, e2};
}

double JTurnPath::DoCalcDistance(const Vec2& p) const {
  const PathPoint ref = DoCalcReferencePoint(p);
  return cross2(ref.tangent(), p - ref.p_G);
}

std::vector<PathPoint> JTurnPath::DoSample(double in, double out, double spacing) const {
  std::vector<PathPoint> pts;
  const double a = -in, b = arcLengthToExit() + out;
  const int n = std::max(1, static_cast<int>(std::ceil((b - a) / spacing)));
  for (int i = 0; i <= n; ++i) pts.push_back(calcPointAtArcLength(a + (b - a) * i / n));
  return pts;
}

// ---------------------------------------------------------------------------
std::shared_ptr<const ReferencePath> makeReferencePath(const ParamReader& r) {
  const std::string type = r.string("type");
  std::shared_ptr<const ReferencePath> path;
  if (type == "lane_change") path = std::make_shared<LaneChangePath>(LaneChangeParams::fromParams(r));
  if (type == "j_turn") path = std::make_shared<JTurnPath>(JTurnParams::fromParams(r));
  if (type == "double_lane_change")
    path = std::make_shared<DoubleLaneChangePath>(DoubleLaneChangeParams::fromParams(r));
  if (path) {
    r.requireAllKeysRead();
    return path;
  }
  throw Error(r.at("type") + ": unknown path type '" + type + "'; known: double_lane_change, j_turn, lane_change");
}

}  // namespace vdyn
