// Handling tests (plugins/handling): ISO 4138 constant radius against the
// linear bicycle's closed form and a long transient; ISO 7401 frequency
// response against sine-steer simulations.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/handling/iso3888.h"
#include "vdyn/handling/iso4138.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/handling/iso7401.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/vehicles/handling_vehicles.h"

using namespace vdyn;

namespace {
const double kDeg = SimTK::Pi / 180;

std::unique_ptr<HandlingBuild> bike(const std::string& tire) {
  BicycleParams p = BicycleParams::fromFile("bicycle.json");
  p.tire_plugin = tire;
  return makeHandlingBicycle(p);
}
}  // namespace

TEST(Iso4138, LinearTireBicycleUndersteerGradientIsTheClosedForm) {
  auto b = bike("linear");
  const Bicycle& bk = *b->bicycle;
  ConstantRadiusSettings set;
  set.radius_m = 100;
  set.speed_start_m_s = 3;
  set.speed_step_m_s = 1;
  set.speed_max_m_s = 8;  // a_y <= 0.64 m/s^2: the linear range
  set.stability = false;
  const ConstantRadiusResult r = runConstantRadius(b->vehicle, set);
  // Linear bicycle (6.1)-(6.9), two tires per axle: delta_f = l / R + K a_y,
  // K = M / l (b / C_f - a / C_r).
  const double M = bk.totalMass(), a = bk.distanceToFrontAxle(), bb = bk.distanceToRearAxle(), l = a + bb;
  const double C = 2 * bk.params().tire.cornering_stiffness_N_per_rad;
  const double K = M / l * (bb / C - a / C);
  std::printf("understeer gradient %.6e rad/(m/s^2) (closed form %.6e), delta at a_y = %.3f: %.6e (l/R + K a_y = %.6e)\n",
              r.understeer_gradient_linear_rad_per_m_s2, K, r.points[0].lateral_accel_m_s2, r.points[0].front_rad,
              l / 100 + K * r.points[0].lateral_accel_m_s2);
  EXPECT_EQ(r.points.size(), 6u);
  EXPECT_FALSE(r.limit_found);
  EXPECT_NEAR(r.understeer_gradient_linear_rad_per_m_s2, K, 1e-3 * std::abs(K));
  // The path radius is the one asked for: U / r = R.
  for (const auto& p : r.points) EXPECT_NEAR(p.path_radius_m, 100.0, 1e-8);
}

TEST(Iso4138, LongTransientEndsOnTheConstantRadiusSteadyState) {
  // Three points of the R = 40 m sweep (a_y = 1.6, 3.6 and 4.9 m/s^2): the constant-radius
  // steady state against a long transient from straight running with the solved angle held.
  for (const double speed : {8.0, 12.0, 14.0}) {
    SCOPED_TRACE("speed " + std::to_string(speed) + " m/s");
    auto b = bike("gim");
    ConstantRadiusSettings set;
    set.radius_m = 40;
    set.speed_start_m_s = set.speed_max_m_s = speed;
    set.stability = false;
    const ConstantRadiusResult r = runConstantRadius(b->vehicle, set);
    ASSERT_EQ(r.points.size(), 1u);
    const ConstantRadiusPoint& p = r.points[0];
    b->vehicle.holdSteering(speed, p.front_rad);
    IntegratorSettings integ;
    integ.accuracy = 1e-8;
    const HandlingHistory h = runHandlingTransient(b->vehicle, speed, 15.0, 0.5, integ);
    const double rT = h.yaw_rate_rad_s.back(), ayT = h.lateral_accel_m_s2.back();
    std::printf("%.0f m/s, front %.6f deg: yaw rate steady %.9f transient %.9f; a_y %.9f / %.9f; "
                "side slip %.9f / %.9f; roll %.9g / %.9g\n",
                speed, p.front_rad / kDeg, p.yaw_rate_rad_s, rT, p.lateral_accel_m_s2, ayT, p.side_slip_rad,
                h.side_slip_rad.back(), p.roll_rad, h.roll_rad.back());
    EXPECT_NEAR(rT, p.yaw_rate_rad_s, 1e-5 * p.yaw_rate_rad_s);
    EXPECT_NEAR(ayT, p.lateral_accel_m_s2, 1e-5 * p.lateral_accel_m_s2);
    EXPECT_NEAR(h.side_slip_rad.back(), p.side_slip_rad, 1e-5 * std::abs(p.side_slip_rad));
    // Path radius of the transient: U / r.
    EXPECT_NEAR(speed / rT, 40.0, 40.0 * 1e-5);
  }
}

TEST(Iso7401, FrequencyResponseMatchesSineSteerSimulations) {
  // Linear tires: the Gim tire's lateral force has a |alpha| kink at zero slip
  // (straight running), so its sine response deviates from the tangent
  // linearisation in proportion to the amplitude (0.4 deg of phase at 0.002 rad).
  auto b = bike(std::getenv("VDYN_TIRE") ? std::getenv("VDYN_TIRE") : "linear");
  const double U = 80.0 / 3.6;
  const std::vector<double> freqs = {0.5, 1.0, 2.0};
  const FrequencyResponseResult fr = calcSteeringFrequencyResponse(b->vehicle, U, freqs);
  IntegratorSettings integ;
  integ.accuracy = 1e-8;
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    const double settle = std::getenv("VDYN_SETTLE") ? std::atof(std::getenv("VDYN_SETTLE")) : 2.0;
    const double amp = std::getenv("VDYN_AMP") ? std::atof(std::getenv("VDYN_AMP")) : 0.002;
    const SineSteerResult s = runSineSteer(b->vehicle, U, freqs[i], amp, integ, 1, settle, 2);
    const FrequencyResponsePoint& l = fr.points[i];
    std::printf("%.2f Hz: yaw gain sim %.6f lin %.6f, phase sim %.4f lin %.4f deg; a_y gain sim %.5f lin %.5f, phase "
                "sim %.4f lin %.4f deg (fit residual %.1e)\n",
                freqs[i], s.yaw_gain_1_per_s, l.yaw_gain_1_per_s, s.yaw_phase_deg, l.yaw_phase_deg,
                s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad, s.ay_phase_deg, l.ay_phase_deg, s.fit_residual);
    EXPECT_NEAR(s.yaw_gain_1_per_s, l.yaw_gain_1_per_s, 0.01 * l.yaw_gain_1_per_s);
    EXPECT_NEAR(s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad, 0.01 * l.ay_gain_m_s2_per_rad);
    EXPECT_NEAR(s.yaw_phase_deg, l.yaw_phase_deg, 0.01 * std::abs(l.yaw_phase_deg));
    EXPECT_NEAR(s.ay_phase_deg, l.ay_phase_deg, 0.01 * std::abs(l.ay_phase_deg));
  }
}

TEST(Iso7401, GimTireFrequencyResponseAboutATurnMatchesSineSteerSimulations) {
  // The seed's Gim tire: about straight running its |alpha| kink at zero slip
  // puts the sine response off the tangent linearisation (1.5 % in a_y gain at
  // 2 Hz). About a steady turn at 2 m/s^2 the tires' slips stay away from
  // zero for a 0.002 rad sine, and the small-signal theory holds: the same
  // 1 % band as the linear tire's.
  auto b = bike("gim");
  const double U = 80.0 / 3.6, ay = 2.0;
  const std::vector<double> freqs = {0.5, 1.0, 2.0};
  const FrequencyResponseResult fr = calcSteeringFrequencyResponse(b->vehicle, U, freqs, ay);
  IntegratorSettings integ;
  integ.accuracy = 1e-8;
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    const SineSteerResult s = runSineSteer(b->vehicle, U, freqs[i], 0.002, integ, 1, 2.0, 2, ay);
    const FrequencyResponsePoint& l = fr.points[i];
    std::printf("about a_y %.1f: %.2f Hz: yaw gain sim %.6f lin %.6f, phase sim %.4f lin %.4f deg; a_y gain sim %.5f "
                "lin %.5f, phase sim %.4f lin %.4f deg\n",
                ay, freqs[i], s.yaw_gain_1_per_s, l.yaw_gain_1_per_s, s.yaw_phase_deg, l.yaw_phase_deg,
                s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad, s.ay_phase_deg, l.ay_phase_deg);
    EXPECT_NEAR(s.yaw_gain_1_per_s, l.yaw_gain_1_per_s, 0.01 * l.yaw_gain_1_per_s);
    EXPECT_NEAR(s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad, 0.01 * l.ay_gain_m_s2_per_rad);
    EXPECT_NEAR(s.yaw_phase_deg, l.yaw_phase_deg, 0.01 * std::abs(l.yaw_phase_deg));
    EXPECT_NEAR(s.ay_phase_deg, l.ay_phase_deg, 0.01 * std::abs(l.ay_phase_deg));
  }
}

TEST(VehicleReport, StaticLoadsBalanceTheWeightAndKinematicsAreConsistent) {
  const VehicleReport r = makeFourWsReport(FourWsParams::fromFile("appendix_a.json"), {-0.08, 0.0, 0.08});
  std::printf("4ws: loads %.2f %.2f %.2f %.2f N (sum %.3f, weight %.3f), c.m. height %.4f m, %d iterations\n",
              r.corner_loads_N[0].second, r.corner_loads_N[1].second, r.corner_loads_N[2].second,
              r.corner_loads_N[3].second, r.total_load_N, r.weight_N, r.com_height_m, r.iterations);
  // The tires carry the weight (the steady-state solver at zero speed is a static equilibrium).
  EXPECT_NEAR(r.total_load_N, r.weight_N, 1e-6 * r.weight_N);
  // Left and right corners mirror each other.
  EXPECT_NEAR(r.corner_loads_N[0].second, r.corner_loads_N[1].second, 1e-6 * r.corner_loads_N[0].second);
  for (const auto& [axle, pts] : r.kinematics) {
    ASSERT_EQ(pts.size(), 3u);
    EXPECT_NEAR(pts[1].track_change_m, 0.0, 1e-12) << axle;
    EXPECT_NEAR(pts[1].recession_m, 0.0, 1e-12) << axle;
    EXPECT_GT(pts[1].wheel_rate_N_per_m, 0.0) << axle;
    std::printf("%s: camber %.4f/%.4f/%.4f deg, track %.5f/%.5f m, rate %.0f N/m, roll centre %.4f m\n", axle.c_str(),
                pts[0].camber_rad / kDeg, pts[1].camber_rad / kDeg, pts[2].camber_rad / kDeg, pts[0].track_change_m,
                pts[2].track_change_m, pts[1].wheel_rate_N_per_m, pts[1].roll_centre_height_m);
  }
}

// ISO 3888-2: the layout of Table 1 from the vehicle width, the cone check on
// prescribed motions, and closed-loop runs that pass and fail.
TEST(Iso3888, LayoutFollowsTheStandardFromTheVehicleWidth) {
  for (double b : {1.6, 1.8, 2.2}) {
    const Iso3888Layout L = Iso3888Layout::make(b, 30.0);
    ASSERT_EQ(L.lanes.size(), 3u);
    const ConeLane &l1 = L.lanes[0], &l3 = L.lanes[1], &l5 = L.lanes[2];
    EXPECT_DOUBLE_EQ(L.endX() - 30.0, 61.0);  // 12 + 13.5 + 11 + 12.5 + 12
    EXPECT_DOUBLE_EQ(l1.x_start_m, 30.0);
    EXPECT_DOUBLE_EQ(l1.x_end_m, 42.0);
    EXPECT_DOUBLE_EQ(l3.x_start_m, 55.5);
    EXPECT_DOUBLE_EQ(l3.x_end_m, 66.5);
    EXPECT_DOUBLE_EQ(l5.x_start_m, 79.0);
    EXPECT_DOUBLE_EQ(l5.x_end_m, 91.0);
    EXPECT_NEAR(l1.width(), 1.1 * b + 0.25, 1e-12);
    EXPECT_NEAR(l3.width(), b + 1.0, 1e-12);
    EXPECT_NEAR(l5.width(), std::max(1.3 * b + 0.25, 3.0), 1e-12);
    EXPECT_NEAR(l1.centre(), 0.0, 1e-12);                 // the vehicle starts on it
    EXPECT_NEAR(l3.y_right_m - l1.y_left_m, 1.0, 1e-12);  // 1 m lateral offset, to the left
    EXPECT_NEAR(l5.y_right_m, l1.y_right_m, 1e-12);       // exit lane on the entry lane's right line
    // The centre path: lane centre to lane centre over each transition.
    const DoubleLaneChangeParams p = L.makeReferencePath(1.0, -1.0);
    const DoubleLaneChangePath path(p);
    EXPECT_NEAR(path.calcY(36.0), l1.centre(), 1e-12);
    EXPECT_NEAR(path.calcY(61.0), l3.centre(), 1e-12);
    EXPECT_NEAR(path.calcY(85.0), l5.centre(), 1e-12);
    EXPECT_DOUBLE_EQ(p.first.start_x_m, 41.0);
    EXPECT_DOUBLE_EQ(p.first.length_m, 15.5);
    // The inside line: 0.1 m from the left line in lane 1, the right line in lane 3.
    const DoubleLaneChangePath inside(L.makeReferencePath(1.0, 0.1));
    EXPECT_NEAR(inside.calcY(36.0), l1.y_left_m - b / 2 - 0.1, 1e-12);
    EXPECT_NEAR(inside.calcY(61.0), l3.y_right_m + b / 2 + 0.1, 1e-12);
    EXPECT_NEAR(inside.calcY(85.0), l5.y_left_m - b / 2 - 0.1, 1e-12);
  }
  EXPECT_NEAR(Iso3888Layout::make(1.8, 0).lanes[2].width(), 3.0, 1e-12);  // 1.3 b + 0.25 = 2.59 < 3 m
}

TEST(Iso3888, ConeCheckFindsTheStruckLines) {
  const double b = 1.8;
  const Iso3888Layout L = Iso3888Layout::make(b, 30.0);
  BodyOutline body;
  body.front_x_m = 2.0, body.rear_x_m = -1.6, body.half_width_m = b / 2;
  // Motion on the lane centres with the body straight in every lane (a jump
  // between lanes in each transition): nothing struck.
  std::vector<double> t, x, y, yaw;
  for (double X = 0; X <= 100; X += 0.1) {
    // Each lane's centre from midway through the transition before it.
    const double front = X + body.front_x_m;
    double yc = 0;
    if (front > L.lanes[0].x_end_m + 0.5 * (L.lanes[1].x_start_m - L.lanes[0].x_end_m)) yc = L.lanes[1].centre();
    if (front > L.lanes[1].x_end_m + 0.5 * (L.lanes[2].x_start_m - L.lanes[1].x_end_m)) yc = L.lanes[2].centre();
    t.push_back(X / 10), x.push_back(X), y.push_back(yc), yaw.push_back(0);
  }
  const ConeCheck ok = checkCones(L, body, t, x, y, yaw);
  EXPECT_TRUE(ok.strikes.empty());
  EXPECT_TRUE(ok.reached_exit);
  // The smallest clearance is the entry lane's: (1.1 b + 0.25 - b) / 2.
  EXPECT_NEAR(ok.min_clearance_m, 0.5 * (0.1 * b + 0.25), 1e-12);
  // Straight on: passes outside the side lane (its right line) and nothing else.
  std::vector<double> y0(t.size(), 0.0);
  const ConeCheck straight = checkCones(L, body, t, x, y0, yaw);
  ASSERT_EQ(straight.strikes.size(), 1u);
  EXPECT_EQ(straight.strikes[0].section, 3);
  EXPECT_EQ(straight.strikes[0].side, "right");
  EXPECT_NEAR(straight.min_clearance_m, -(0.5 * (1.1 * b + 0.25) + 1.0 + 0.5 * b), 1e-12);
  // Yawed 15 deg in the entry lane: the front-left corner is 2 sin 15 + 0.9 cos 15 = 1.387 m
  // left of the centre, beyond the left line at 1.24 m.
  std::vector<double> yawed(t.size(), 15 * kDeg);
  const ConeCheck turn = checkCones(L, body, t, x, y, yawed);
  ASSERT_FALSE(turn.strikes.empty());
  EXPECT_EQ(turn.strikes[0].section, 1);
  EXPECT_EQ(turn.strikes[0].side, "left");
}

TEST(Iso3888, ClosedLoopBicyclePassesSlowAndStrikesConesFast) {
  PluginRegistry& reg = standardRegistry();
  const SceneDescription scene = SceneDescription::fromFile("scenes/iso3888_bicycle.json", reg);
  auto b = bike("gim");
  Iso3888Settings set;
  const BodyOutline body = b->footprint.body(set);
  const Iso3888Layout L = Iso3888Layout::make(2 * body.half_width_m, set.entry_x_m);
  const Iso3888Run slow = runIso3888(scene, set, L, body, 10.0);
  // Faster: the controller still brings it through the course (no spin-out,
  // the path kept), but the body overshoots the side lane and strikes cones.
  const Iso3888Run fast = runIso3888(scene, set, L, body, 13.0);
  std::printf("slow: completed %d pass %d, %zu strikes, clearance %.3f m, exit %.3f m/s; fast: completed %d pass %d, "
              "%zu strikes, clearance %.3f m %s\n",
              slow.completed, slow.pass, slow.cones.strikes.size(), slow.cones.min_clearance_m, slow.exit_speed_m_s,
              fast.completed, fast.pass, fast.cones.strikes.size(), fast.cones.min_clearance_m, fast.reason.c_str());
  EXPECT_TRUE(slow.pass) << slow.reason;
  EXPECT_GT(slow.cones.min_clearance_m, 0.0);
  // Coasting: no drive, so the exit speed is at most the entry speed.
  EXPECT_LE(slow.exit_speed_m_s, 10.0 + 1e-9);
  EXPECT_TRUE(fast.completed) << fast.reason;
  EXPECT_FALSE(fast.cones.strikes.empty());
  EXPECT_LT(fast.cones.min_clearance_m, 0.0);
  EXPECT_FALSE(fast.pass);
}
