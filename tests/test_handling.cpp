// Handling tests (plugins/handling): ISO 4138 constant radius against the
// linear bicycle's closed form and a long transient; ISO 7401 frequency
// response against sine-steer simulations.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/handling/iso4138.h"
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
  auto b = bike("gim");
  ConstantRadiusSettings set;
  set.radius_m = 40;
  set.speed_start_m_s = set.speed_max_m_s = 12;  // a_y = 3.6 m/s^2
  set.stability = false;
  const ConstantRadiusResult r = runConstantRadius(b->vehicle, set);
  ASSERT_EQ(r.points.size(), 1u);
  const ConstantRadiusPoint& p = r.points[0];
  // The transient from straight running with the solved angle held.
  b->vehicle.holdSteering(12, p.front_rad);
  IntegratorSettings integ;
  integ.accuracy = 1e-8;
  const HandlingHistory h = runHandlingTransient(b->vehicle, 12, 15.0, 0.5, integ);
  const double rT = h.yaw_rate_rad_s.back(), ayT = h.lateral_accel_m_s2.back();
  std::printf("front %.6f deg: yaw rate steady %.9f transient %.9f; a_y %.9f / %.9f; side slip %.9f / %.9f; roll %.9g / %.9g\n",
              p.front_rad / kDeg, p.yaw_rate_rad_s, rT, p.lateral_accel_m_s2, ayT, p.side_slip_rad,
              h.side_slip_rad.back(), p.roll_rad, h.roll_rad.back());
  EXPECT_NEAR(rT, p.yaw_rate_rad_s, 1e-5 * p.yaw_rate_rad_s);
  EXPECT_NEAR(ayT, p.lateral_accel_m_s2, 1e-5 * p.lateral_accel_m_s2);
  EXPECT_NEAR(h.side_slip_rad.back(), p.side_slip_rad, 1e-5 * std::abs(p.side_slip_rad));
  // Path radius of the transient: U / r.
  EXPECT_NEAR(12.0 / rT, 40.0, 40.0 * 1e-5);
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
