// Reference paths of the closed-loop path control: the lane change (7.6)-(7.8)
// and the J-turn (7.19)-(7.24) against their formulas, with the continuity the
// seed asks for (slope and curvature at the lane change's ends and midpoint,
// the direction along the circle and at the exit).
#include <cmath>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/path/path.h"

using namespace vdyn;
using SimTK::Vec2;

namespace {
LaneChangePath laneChange() {
  LaneChangeParams p;
  p.start_x_m = 10;
  p.start_y_m = 1;
  p.length_m = 40;
  p.shift_m = 4;
  return LaneChangePath(p);
}
}  // namespace

TEST(LaneChangePath, ValuesFollowTheQuarticPair) {
  const LaneChangePath lc = laneChange();  // X0 = 10, h = 20, D = 4
  EXPECT_DOUBLE_EQ(lc.calcY(0.0), 1.0);
  EXPECT_DOUBLE_EQ(lc.calcY(10.0), 1.0);
  // u = 1/2 on the first half: D (1/8 - 1/32) = 0.375 (7.7a)
  EXPECT_NEAR(lc.calcY(20.0), 1.0 + 4 * (0.125 - 0.0625 / 2), 1e-14);
  EXPECT_NEAR(lc.calcY(30.0), 3.0, 1e-14);  // midpoint: Y0 + D/2
  // u' = 1/2 on the second half (7.7b): the point mirror of X = 20
  EXPECT_NEAR(lc.calcY(40.0), 5.0 - 4 * (0.125 - 0.0625 / 2), 1e-14);
  EXPECT_DOUBLE_EQ(lc.calcY(50.0), 5.0);
  EXPECT_DOUBLE_EQ(lc.calcY(80.0), 5.0);
  // (7.8): slope D/h (3 u^2 - 2 u^3); at u = 1/2: 0.2 * 0.5
  EXPECT_NEAR(lc.calcSlope(20.0), 0.2 * 0.5, 1e-14);
  EXPECT_NEAR(lc.calcSlope(30.0), 0.2, 1e-14);  // steepest at the midpoint: D/h
}

TEST(LaneChangePath, SlopeAndSecondDerivativeMatchFiniteDifferences) {
  const LaneChangePath lc = laneChange();
  const double h = 1e-4;
  for (double X = 10.0 + 2 * h; X < 50.0 - 2 * h; X += 0.731) {
    EXPECT_NEAR(lc.calcSlope(X), (lc.calcY(X + h) - lc.calcY(X - h)) / (2 * h), 1e-9) << "X = " << X;
    EXPECT_NEAR(lc.calcSecondDerivative(X), (lc.calcSlope(X + h) - lc.calcSlope(X - h)) / (2 * h), 1e-9)
        << "X = " << X;
  }
}

TEST(LaneChangePath, SlopeAndCurvatureAreContinuousAtTheEndsAndMidpoint) {
  const LaneChangePath lc = laneChange();
  const double eps = 1e-9;
  for (double X : {10.0, 30.0, 50.0}) {
    EXPECT_NEAR(lc.calcY(X - eps), lc.calcY(X + eps), 1e-8) << "X = " << X;
    EXPECT_NEAR(lc.calcSlope(X - eps), lc.calcSlope(X + eps), 1e-8) << "X = " << X;
    EXPECT_NEAR(lc.calcSecondDerivative(X - eps), lc.calcSecondDerivative(X + eps), 1e-8) << "X = " << X;
  }
  // (7.6): zero slope and curvature at both ends; zero curvature at the midpoint
  // (the two quartics' Y'' = 6 D u (1 - u) / h^2 vanish at u = 1).
  for (double X : {10.0, 30.0, 50.0}) {
    EXPECT_NEAR(lc.calcSecondDerivative(X), 0.0, 1e-15);
    EXPECT_NEAR(lc.calcReferencePoint(Vec2(X, 0)).curvature_per_m, 0.0, 1e-15);
  }
  EXPECT_NEAR(lc.calcSlope(10.0), 0.0, 1e-15);
  EXPECT_NEAR(lc.calcSlope(50.0), 0.0, 1e-15);
  // Curvature Y'' / (1 + Y'^2)^1.5 and heading atan(Y') at a quarter point.
  const PathPoint p = lc.calcReferencePoint(Vec2(20.0, -3.0));
  const double s = 0.1, k = 4.0 / 400 * 6 * 0.5 * 0.5;
  EXPECT_NEAR(p.p_G[1], lc.calcY(20.0), 1e-15);
  EXPECT_NEAR(p.heading_rad, std::atan(s), 1e-14);
  EXPECT_NEAR(p.curvature_per_m, k / std::pow(1 + s * s, 1.5), 1e-15);
}

TEST(LaneChangePath, ErrorsAreTheSeedsPositionAndSlopeErrors) {
  const LaneChangePath lc = laneChange();
  // (7.9)-(7.10): e1 = y - Y(x), e2 = y'/x' - dY/dX(x).
  const PathErrors e = lc.calcErrors(Vec2(30.0, 3.5), Vec2(10.0, 1.5));
  EXPECT_NEAR(e.position_m, 0.5, 1e-14);
  EXPECT_NEAR(e.slope, 0.15 - 0.2, 1e-14);
  // The closest-point distance: a point off the path by 0.3 m along its normal.
  const double X = 23.0, s = lc.calcSlope(X);
  const Vec2 n = Vec2(-s, 1) / std::sqrt(1 + s * s);
  EXPECT_NEAR(lc.calcDistance(Vec2(X, lc.calcY(X)) + 0.3 * n), 0.3, 1e-10);
  EXPECT_NEAR(lc.calcDistance(Vec2(X, lc.calcY(X)) - 0.3 * n), -0.3, 1e-10);
  EXPECT_EQ(test::errorOf([&] { lc.calcErrors(Vec2(30, 3), Vec2(-1, 0)); }),
            "lane change path: the vehicle must move along +X for the slope error (7.10), got x' = -1 m/s");
  EXPECT_EQ(test::errorOf([&] { lc.calcErrors(Vec2(NAN, 3), Vec2(1, 0)); }),
            "path: position must be finite, got (nan, 3)");
}

TEST(JTurnPath, GeometryOfTheCircleAndItsLines) {
  JTurnParams p;
  p.entry_length_m = 20;
  p.radius_m = 30;
  p.exit_angle_rad = SimTK::Pi / 2;
  const JTurnPath j(p);
  EXPECT_NEAR(j.centre()[0], 20.0, 1e-14);
  EXPECT_NEAR(j.centre()[1], 30.0, 1e-14);
  EXPECT_NEAR(j.exitPoint()[0], 50.0, 1e-13);
  EXPECT_NEAR(j.exitPoint()[1], 30.0, 1e-13);
  const PathPoint mid = j.calcPointAtArcLength(20 + 30 * SimTK::Pi / 4);
  EXPECT_NEAR(mid.p_G[0], 20 + 30 * std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(mid.p_G[1], 30 - 30 * std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(mid.heading_rad, SimTK::Pi / 4, 1e-14);
  EXPECT_NEAR(mid.curvature_per_m, 1.0 / 30, 1e-15);
  EXPECT_EQ(j.calcPointAtArcLength(10).curvature_per_m, 0.0);
  EXPECT_EQ(j.calcPointAtArcLength(200).curvature_per_m, 0.0);
  // A right turn mirrors it.
  p.turn_left = false;
  const JTurnPath r(p);
  EXPECT_NEAR(r.centre()[1], -30.0, 1e-14);
  EXPECT_NEAR(r.calcPointAtArcLength(30).curvature_per_m, -1.0 / 30, 1e-15);
}

TEST(JTurnPath, DirectionIsContinuousAlongTheCircleAndAtTheExit) {
  // Start heading 2.5 rad and a 150 deg turn: the direction passes pi, where
  // atan2 jumps; the path's heading must not.
  JTurnParams p;
  p.start_x_m = 3;
  p.start_y_m = -2;
  p.start_heading_rad = 2.5;
  p.entry_length_m = 10;
  p.radius_m = 25;
  p.exit_angle_rad = 150 * SimTK::Pi / 180;
  const JTurnPath j(p);
  const double ds = 0.05, sEnd = j.arcLengthToExit() + 20;
  PathPoint prev = j.calcPointAtArcLength(0);
  for (double s = ds; s <= sEnd; s += ds) {
    const PathPoint q = j.calcPointAtArcLength(s);
    EXPECT_LE((q.p_G - prev.p_G).norm(), ds * (1 + 1e-9)) << "s = " << s;   // position continuous
    EXPECT_LE(std::abs(q.heading_rad - prev.heading_rad), ds / 25 * (1 + 1e-9)) << "s = " << s;  // <= ds / R
    // The reference point of a path point is itself, with the same heading.
    const PathPoint ref = j.calcReferencePoint(q.p_G);
    EXPECT_NEAR((ref.p_G - q.p_G).norm(), 0.0, 1e-9) << "s = " << s;
    EXPECT_NEAR(wrapAngle(ref.heading_rad - q.heading_rad), 0.0, 1e-9) << "s = " << s;
    prev = q;
  }
  EXPECT_NEAR(prev.heading_rad, 2.5 + 150 * SimTK::Pi / 180, 1e-12);  // unwrapped past pi
  // At the exit: position and direction continuous, curvature steps from 1/R to 0.
  const double sX = j.arcLengthToExit();
  const PathPoint a = j.calcPointAtArcLength(sX - 1e-9), b = j.calcPointAtArcLength(sX + 1e-9);
  EXPECT_NEAR((a.p_G - b.p_G).norm(), 0.0, 1e-8);
  EXPECT_NEAR(a.heading_rad, b.heading_rad, 1e-9);
  EXPECT_NEAR(a.curvature_per_m, 1.0 / 25, 1e-15);
  EXPECT_EQ(b.curvature_per_m, 0.0);
}

TEST(JTurnPath, ErrorsAreRadialOffsetAndDirectionError) {
  JTurnParams p;
  p.entry_length_m = 20;
  p.radius_m = 30;
  p.exit_angle_rad = SimTK::Pi / 2;
  const JTurnPath j(p);
  const Vec2 c = j.centre();
  // A point 0.4 m outside the circle at polar angle -60 deg (30 deg travelled):
  // e1 = R - |p - c| = -0.4 (right of a left turn) (7.19); moving 0.1 rad left
  // of the tangent (7.21)-(7.24).
  const double th = -SimTK::Pi / 3, tangent = th + SimTK::Pi / 2;
  const Vec2 pt = c + 30.4 * Vec2(std::cos(th), std::sin(th));
  const PathErrors e = j.calcErrors(pt, 12.0 * Vec2(std::cos(tangent + 0.1), std::sin(tangent + 0.1)));
  EXPECT_NEAR(e.position_m, -0.4, 1e-12);
  EXPECT_NEAR(e.slope, 0.1, 1e-12);
  EXPECT_NEAR(j.calcDistance(pt), -0.4, 1e-12);
  // The direction error stays continuous where atan2 of the velocity jumps:
  // after the exit the tangent points along +Y (pi/2); a velocity at pi - 0.01
  // and one at -pi + 0.01 differ by 0.02 rad, not 2 pi.
  JTurnParams q = p;
  q.exit_angle_rad = SimTK::Pi;  // U-turn: the exit line heads along -X
  const JTurnPath u(q);
  const Vec2 onExit = u.exitPoint() + Vec2(-5, 0.2);
  const double e2a = u.calcErrors(onExit, Vec2(std::cos(SimTK::Pi - 0.01), std::sin(SimTK::Pi - 0.01))).slope;
  const double e2b = u.calcErrors(onExit, Vec2(std::cos(-SimTK::Pi + 0.01), std::sin(-SimTK::Pi + 0.01))).slope;
  EXPECT_NEAR(e2a, -0.01, 1e-12);
  EXPECT_NEAR(e2b, 0.01, 1e-12);
  // On the exit line travelled along -X, left is -Y: 0.2 m in +Y is right of it.
  EXPECT_NEAR(u.calcErrors(onExit, Vec2(-1, 0)).position_m, -0.2, 1e-12);
  // On the entry line, 0.3 m left of it.
  EXPECT_NEAR(j.calcErrors(Vec2(5, 0.3), Vec2(12, 0)).position_m, 0.3, 1e-14);
}

TEST(ReferencePath, DataFileErrorsNameTheKey) {
  auto make = [](const Json& j) { return makeReferencePath(ParamReader::fromJson(j, "scene.json path")); };
  EXPECT_EQ(test::errorOf([&] { make({{"type", "spiral"}}); }),
            "scene.json path: type: unknown path type 'spiral'; known: double_lane_change, j_turn, lane_change");
  EXPECT_EQ(test::errorOf([&] {
              make({{"type", "j_turn"}, {"entry_length_m", 10}, {"radius_m", 30}, {"exit_angle_deg", 200}});
            }),
            "j-turn exit angle must be in (0, 180] deg, got 200 deg");
  EXPECT_EQ(test::errorOf([&] { make({{"type", "lane_change"}, {"length_m", -40}, {"shift_m", 4}}); }),
            "lane change length_m must be positive, got -40");
  EXPECT_EQ(make({{"type", "lane_change"}, {"length_m", 40}, {"shift_m", 4}})->type(), "lane_change");
}
