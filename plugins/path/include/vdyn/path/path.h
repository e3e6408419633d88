#pragma once
// Reference paths of the seed's closed-loop path control (chapter 7; docs/equations.md
// "Path control"): the lane change (7.6)-(7.8) and the J-turn, a circle with an exit
// angle and a tangent line after it (7.19)-(7.24). Ground plane (X, Y), m; the
// vehicle travels along +X at the start. Behind one interface: for any point of
// the plane, the reference point the seed's errors refer to, with its tangent
// direction and curvature; the seed's position and slope errors; the
// geometric (closest-point) distance to the path.
//
// Sign conventions (both paths): curvature > 0 turning left; position error
// > 0 when the vehicle is to the left of the path; slope error > 0 when it
// heads to the left of the path's tangent. With these the control law
// delta'' = -(K1 e1 + ...) (7.17) steers right when the vehicle is left.
#include <memory>
#include <string>
#include <vector>

#include <SimTKcommon.h>

#include "vdyn/core/params.h"

namespace vdyn {

/// A point of a reference path.
struct PathPoint {
  SimTK::Vec2 p_G{0, 0};        ///< position (X, Y) in the ground plane, m
  double heading_rad = 0;       ///< tangent direction atan2(dY, dX), rad, continuous along the path
  double curvature_per_m = 0;   ///< signed curvature, 1/m (> 0 turning left)
  SimTK::Vec2 tangent() const { return {std::cos(heading_rad), std::sin(heading_rad)}; }
};

/// The seed's errors of a vehicle point and velocity against the path.
struct PathErrors {
  double position_m = 0;  ///< e1 (7.9)/(7.19): > 0 left of the path, m
  /// e2 (7.10)/(7.21): lane change, slope dY/dX difference (dimensionless);
  /// J-turn, angle between the direction of travel and the tangent, rad.
  double slope = 0;
};

class ReferencePath {
 public:
  virtual ~ReferencePath() = default;
  /// "lane_change" or "j_turn".
  virtual std::string type() const = 0;

  /// The path point the errors of a vehicle at p_G refer to: the lane change's
  /// point at the same X (7.9); the J-turn's radial projection on the circle
  /// (7.19) or the foot of the perpendicular on the entry or exit line.
  PathPoint calcReferencePoint(const SimTK::Vec2& p_G) const;
  /// The seed's position and slope errors of a vehicle at p_G moving with
  /// v_G (m/s): (7.9)-(7.10) for the lane change, (7.19)-(7.24) for the J-turn.
  /// Throws Error if p_G or v_G is not finite, or (lane change) the vehicle
  /// does not move along +X.
  PathErrors calcErrors(const SimTK::Vec2& p_G, const SimTK::Vec2& v_G) const;
  /// Signed distance from p_G to the closest path point (> 0 left of the
  /// path), m: the geometric path error the studies report.
  double calcDistance(const SimTK::Vec2& p_G) const;
  /// Points along the path every `spacing_m` (arc length, approximately), from
  /// `lead_in_m` before its start to `lead_out_m` after its end (for plots).
  std::vector<PathPoint> sample(double lead_in_m, double lead_out_m, double spacing_m) const;

 protected:
  virtual PathPoint DoCalcReferencePoint(const SimTK::Vec2& p_G) const = 0;
  virtual PathErrors DoCalcErrors(const SimTK::Vec2& p_G, const SimTK::Vec2& v_G) const = 0;
  virtual double DoCalcDistance(const SimTK::Vec2& p_G) const = 0;
  virtual std::vector<PathPoint> DoSample(double lead_in_m, double lead_out_m, double spacing_m) const = 0;
};

/// Lane change from (X0, Y0) to (Xf, Yf) (7.6)-(7.8): h = (Xf - X0) / 2,
/// D = Yf - Y0, u = (X - X0) / h on the first half and u' = (Xf - X) / h on
/// the second,
///   Y = Y0 + D (u^3 - u^4 / 2)    for X0 <= X <= X0 + h,        (7.7a)
///   Y = Yf - D (u'^3 - u'^4 / 2)  for X0 + h <= X <= Xf,         (7.7b)
/// straight (Y0, Yf) before and after. Slope, curvature and Y'' are zero at
/// both ends (7.6) and continuous at the midpoint.
struct LaneChangeParams {
  double start_x_m = 0;    ///< X0, m
  double start_y_m = 0;    ///< Y0, m
  double length_m = 40;    ///< Xf - X0 > 0, m
  double shift_m = 4;      ///< D = Yf - Y0, m (> 0 to the left)
  void validate() const;
  /// Keys start_x_m, start_y_m, length_m, shift_m.
  static LaneChangeParams fromParams(const ParamReader& r);
};

class LaneChangePath : public ReferencePath {
 public:
  explicit LaneChangePath(const LaneChangeParams& p);
  std::string type() const override { return "lane_change"; }
  const LaneChangeParams& params() const { return p_; }
  /// Y(X), dY/dX, d2Y/dX2 of (7.7)-(7.8).
  double calcY(double X) const;
  double calcSlope(double X) const;
  double calcSecondDerivative(double X) const;

 protected:
  PathPoint DoCalcReferencePoint(const SimTK::Vec2& p_G) const override;
  PathErrors DoCalcErrors(const SimTK::Vec2& p_G, const SimTK::Vec2& v_G) const override;
  double DoCalcDistance(const SimTK::Vec2& p_G) const override;
  std::vector<PathPoint> DoSample(double lead_in_m, double lead_out_m, double spacing_m) const override;

 private:
  LaneChangeParams p_;
  double h_;
};

/// Two lane changes (7.6)-(7.8) in sequence along X (a double lane change, e.g.
/// the ISO 3888-2 course): Y(X) = Y0 + D1 f1(X) + D2 f2(X), each f the unit
/// lane change of (7.7) over its own [X0_i, X0_i + L_i]; the second starts
/// where or after the first ends. Errors as the lane change's (7.9)-(7.10).
struct DoubleLaneChangeParams {
  double start_y_m = 0;   ///< Y0, m
  LaneChangeParams first, second;  ///< their start_y_m is ignored (taken as Y0 and Y0 + D1)
  void validate() const;
  /// Keys start_y_m, first {start_x_m, length_m, shift_m}, second {...}.
  static DoubleLaneChangeParams fromParams(const ParamReader& r);
};

class DoubleLaneChangePath : public ReferencePath {
 public:
  explicit DoubleLaneChangePath(const DoubleLaneChangeParams& p);
  std::string type() const override { return "double_lane_change"; }
  const DoubleLaneChangeParams& params() const { return p_; }
  double calcY(double X) const;
  double calcSlope(double X) const;
  double calcSecondDerivative(double X) const;

 protected:
  PathPoint DoCalcReferencePoint(const SimTK::Vec2& p_G) const override;
  PathErrors DoCalcErrors(const SimTK::Vec2& p_G, const SimTK::Vec2& v_G) const override;
  double DoCalcDistance(const SimTK::Vec2& p_G) const override;
  std::vector<PathPoint> DoSample(double lead_in_m, double lead_out_m, double spacing_m) const override;

 private:
  DoubleLaneChangeParams p_;
  std::unique_ptr<LaneChangePath> a_, b_;
};

/// J-turn (7.19)-(7.24), Figures 7.9-7.10 and 8.11: an entry line from the
/// start point along the start heading, a circle of radius R tangent to it,
/// followed for the exit angle alpha_F (the heading change), then the tangent
/// line at the exit. The seed starts on the circle; the entry line lets the
/// vehicle start straight and the controller's look-ahead act before the
/// circle (a stated choice; the seed's Figure 8.12 shows a straight approach).
struct JTurnParams {
  double start_x_m = 0, start_y_m = 0;  ///< start of the entry line, m
  double start_heading_rad = 0;         ///< direction of the entry line, rad
  double entry_length_m = 20;           ///< length of the entry line, m (>= 0)
  double radius_m = 30;                 ///< R > 0, m
  double exit_angle_rad = SimTK::Pi / 2;  ///< alpha_F in (0, pi], rad
  bool turn_left = true;                ///< circle centre to the left of the entry line
  void validate() const;
  /// Keys start_x_m, start_y_m, start_heading_rad, entry_length_m, radius_m,
  /// exit_angle_deg (the data files give the exit angle in degrees), turn
  /// ("left" or "right").
  static JTurnParams fromParams(const ParamReader& r);
};

class JTurnPath : public ReferencePath {
 public:
  explicit JTurnPath(const JTurnParams& p);
  std::string type() const override { return "j_turn"; }
  const JTurnParams& params() const { return p_; }
  const SimTK::Vec2& centre() const { return c_; }
  const SimTK::Vec2& entryPoint() const { return entry_; }
  const SimTK::Vec2& exitPoint() const { return exit_; }
  /// The path point at arc length s_m from the start (negative: before the
  /// start on the entry line's extension; beyond the exit: on the exit line).
  PathPoint calcPointAtArcLength(double s_m) const;
  double arcLengthToExit() const { return p_.entry_length_m + p_.radius_m * p_.exit_angle_rad; }

 protected:
  PathPoint DoCalcReferencePoint(const SimTK::Vec2& p_G) const override;
  PathErrors DoCalcErrors(const SimTK::Vec2& p_G, const SimTK::Vec2& v_G) const override;
  double DoCalcDistance(const SimTK::Vec2& p_G) const override;
  std::vector<PathPoint> DoSample(double lead_in_m, double lead_out_m, double spacing_m) const override;

 private:
  enum class Part { Entry, Circle, Exit };
  Part partOf(const SimTK::Vec2& p_G) const;
  JTurnParams p_;
  double sign_;  // +1 left turn, -1 right turn
  SimTK::Vec2 t0_, entry_, c_, exit_, tF_;
};

/// Angle wrapped to (-pi, pi].
double wrapAngle(double a_rad);

/// {"type": "lane_change", ...LaneChangeParams keys}, {"type": "double_lane_change",
/// ...DoubleLaneChangeParams keys} or {"type": "j_turn", ...}.
/// Throws Error naming the key for an unknown type.
std::shared_ptr<const ReferencePath> makeReferencePath(const ParamReader& r);

}  // namespace vdyn
