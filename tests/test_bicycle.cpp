// Nonlinear bicycle (seed section 7.1): model size, and agreement with the
// linear bicycle's closed form where the model is linear.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "vdyn/core/simulation.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/vehicles/bicycle.h"

using namespace vdyn;

namespace {
BicycleParams nominal() { return BicycleParams::fromFile("bicycle.json"); }
}  // namespace

TEST(Bicycle, ModelSize) {
  Bicycle bike(nominal());
  const SimTK::State s0 = bike.makeInitialState(10.0);
  // Joint coordinates: chassis 6 + steer 1 + two spins = 9 (seed 7.1).
  EXPECT_EQ(s0.getNU(), 9);
  EXPECT_EQ(bike.degreesOfFreedom(s0), 9);
  bike.addFrontSteering("front_steer", std::make_shared<HoldCommand>(0.0));
  const SimTK::State s1 = bike.makeInitialState(10.0);
  EXPECT_EQ(bike.degreesOfFreedom(s1), 8);  // the steering angle is prescribed
  // App. A masses: chassis 800 + front corners 2 x 26 + rear corners 2 x 36, plus the fork.
  EXPECT_DOUBLE_EQ(bike.totalMass(), 924.0 + bike.params().fork.mass_kg);
}

TEST(Bicycle, LinearTiresMatchTheLinearBicycleClosedForm) {
  BicycleParams p = nominal();
  p.tire = p.tire.linearised();
  Bicycle bike(p);
  const double U = 10.0, delta = 0.5 * SimTK::Pi / 180;
  bike.addFrontSteering("front_steer", std::make_shared<SmoothStepCommand>(0.0, delta, 0.2, 0.5));
  bike.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", U));
  SimTK::State s = bike.makeInitialState(U);
  SimulationSettings sim;
  sim.t_end_s = 8.0;
  sim.report_interval_s = 0;
  sim.integrator.accuracy = 1e-7;
  simulate(bike.getScene(), s, sim);
  const double r = bike.getScene().evalOutput("chassis.yaw_rate_rad_s", s);
  // Linear bicycle (6.1)-(6.9) with two tires per axle: C_f = C_r = 2 C_a.
  const double M = bike.totalMass(), a = bike.distanceToFrontAxle(), b = bike.distanceToRearAxle(), L = a + b;
  const double C = 2 * p.tire.getNumber("cornering_stiffness_N_per_rad");
  const double rLinear = delta * U / (L + M * U * U / L * (b / C - a / C));
  std::printf("yaw rate: nonlinear bicycle %.6f rad/s, linear closed form %.6f rad/s (%.3f %%)\n", r, rLinear,
              100 * (r - rLinear) / rLinear);
  EXPECT_NEAR(r, rLinear, 0.02 * rLinear);
  EXPECT_NEAR(bike.getScene().evalOutput("chassis.roll_rate_rad_s", s), 0.0, 1e-4);  // steady
}
