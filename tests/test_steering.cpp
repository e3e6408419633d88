// Steering commands: the smooth step (7.4) and step sequences, with their rate
// and acceleration checked against finite differences of the angle.
#include <cmath>

#include <gtest/gtest.h>

#include "vdyn/steering/steering.h"

using namespace vdyn;

namespace {
/// Largest mismatch between the analytic rate/acceleration and central
/// differences (h = 1e-5 s: truncation ~h^2 * d''' ~ 1e-8, round-off ~eps/h^2 * delta ~ 1e-7).
void checkDerivatives(const SmoothStepCommand& c, double t0, double t1) {
  const double h = 1e-5;
  for (double t = t0 + 2 * h; t < t1 - 2 * h; t += 0.0137) {
    const double rateFd = (c.calcAt(t + h).angle_rad - c.calcAt(t - h).angle_rad) / (2 * h);
    const double accFd = (c.calcAt(t + h).rate_rad_s - c.calcAt(t - h).rate_rad_s) / (2 * h);
    EXPECT_NEAR(c.calcAt(t).rate_rad_s, rateFd, 1e-7) << "t = " << t;
    EXPECT_NEAR(c.calcAt(t).accel_rad_s2, accFd, 1e-6) << "t = " << t;
  }
}
}  // namespace

TEST(SteeringCommand, SmoothStepValuesAndDerivatives) {
  const SmoothStepCommand c(0.01, 0.05, 0.5, 1.5);
  EXPECT_DOUBLE_EQ(c.calcAt(0.0).angle_rad, 0.01);
  EXPECT_DOUBLE_EQ(c.calcAt(2.0).angle_rad, 0.06);
  // Half way, s = 1/2: 6/4 - 8/8 + 3/16 = 11/16 of the step.
  EXPECT_NEAR(c.calcAt(1.25).angle_rad, 0.01 + 0.05 * 11.0 / 16.0, 1e-15);
  EXPECT_NEAR(c.calcAt(2.0 - 1e-12).rate_rad_s, 0.0, 1e-12);   // rate zero at the end
  EXPECT_NEAR(c.calcAt(0.5 + 1e-12).accel_rad_s2, 12 * 0.05 / (1.5 * 1.5), 1e-9);  // (7.5) at the start
  checkDerivatives(c, 0.5, 2.0);
}

TEST(SteeringCommand, LaneChangeSequenceReturnsToZero) {
  const double d = 0.05;
  const StepSequenceCommand c(0.0, {{0.5, 0.5, d}, {1.5, 1.0, -2 * d}, {3.0, 0.5, d}});
  EXPECT_NEAR(c.calcAt(1.25).angle_rad, d, 1e-15);
  EXPECT_NEAR(c.calcAt(2.75).angle_rad, -d, 1e-15);
  EXPECT_NEAR(c.calcAt(4.0).angle_rad, 0.0, 1e-15);
  EXPECT_NEAR(c.calcAt(4.0).rate_rad_s, 0.0, 1e-15);
}
