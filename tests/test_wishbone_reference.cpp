// vdyn's App. A double-wishbone corner against the independent kinematics
// reference (tests/reference): the reduced corner places its knuckle exactly
// on the closed loop for q = [s, delta] (test_reduced_corner checks the
// constrained model's joints close on it), so its wheel centre and spin axis
// at each (s, delta) must be the reference's at the same wheel travel and
// steer angle (A.1). The reference's hardpoints are the corner's own joint
// points at s = delta = 0, read from the assembled state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "reference/suspension_kinematics.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/vehicles/reduced_wishbone.h"

namespace kr = vdyn::kinematics_reference;

namespace {

kr::Vec3 arr(const SimTK::Vec3& v) { return {v[0], v[1], v[2]}; }

}  // namespace

TEST(WishboneReference, AppendixACornersMatchTheReference) {
  vdyn::WheeledVehicleParams p = vdyn::WheeledVehicleParams::fromFile("appendix_a.json");
  p.formulation = "reduced";
  const vdyn::WheeledVehicle car(p);
  const SimTK::MultibodySystem& sys = car.getScene().getSystem();
  SimTK::State s = car.makeInitialState();
  double worst_m = 0.0, worst_axis = 0.0;
  for (int c : {vdyn::RF, vdyn::LF, vdyn::RR, vdyn::LR}) {
    const vdyn::DoubleWishboneParams& cp = car.cornerParams(c);
    const vdyn::ReducedWishboneCorner& rc = car.reducedCorner(c);
    vdyn::setReducedCornerPosition(s, rc, 0.0, 0.0);
    sys.realize(s, SimTK::Stage::Position);
    const SimTK::Transform X_CK0 = rc.knuckle.findBodyTransformInAnotherBody(s, car.chassis());
    kr::DoubleWishboneHardpoints hp;
    hp.spindle = arr(X_CK0.p());  // the wheel turns about the knuckle origin
    hp.lca_f = arr(cp.lower_pivot.parent_point_m);
    hp.lca_b = arr(cp.lower_pivot.parent_axis_point_m);
    hp.lca_u = arr(X_CK0 * cp.lower_ball.child_point_m);
    hp.uca_f = arr(cp.upper_pivot.parent_point_m);
    hp.uca_b = arr(cp.upper_pivot.parent_axis_point_m);
    hp.uca_u = arr(X_CK0 * cp.upper_ball.child_point_m);
    const double side = hp.spindle[1] < 0 ? -1.0 : 1.0;
    const SimTK::Vec3 out0 = side * (X_CK0.R() * cp.wheel_spin_axis);  // spin axis, outward
    hp.camber_rad = std::asin(-out0[2]);
    hp.toe_in_rad = std::atan2(out0[0], side * out0[1]);
    for (double sq : {-0.12, -0.05, 0.04, 0.1})
      for (double delta : {-0.3, 0.0, 0.08, 0.3}) {
        vdyn::setReducedCornerPosition(s, rc, sq, delta);
        sys.realize(s, SimTK::Stage::Position);
        const SimTK::Transform X_CK = rc.knuckle.findBodyTransformInAnotherBody(s, car.chassis());
        const kr::WheelKinematics k =
            kr::doubleWishboneKinematicsKnuckleSteer(hp, X_CK.p()[2] - hp.spindle[2], delta);
        const SimTK::Vec3 out = side * (X_CK.R() * cp.wheel_spin_axis);
        for (int i = 0; i < 3; ++i) {
          worst_m = std::max(worst_m, std::fabs(k.wheel_centre_m[i] - X_CK.p()[i]));
          worst_axis = std::max(worst_axis, std::fabs(k.spin_axis_out[i] - out[i]));
          EXPECT_NEAR(k.wheel_centre_m[i], X_CK.p()[i], 1e-11)
              << car.cornerName(c) << " s " << sq << " delta " << delta << " axis " << i;
          EXPECT_NEAR(k.spin_axis_out[i], out[i], 1e-11)
              << car.cornerName(c) << " s " << sq << " delta " << delta << " axis " << i;
        }
        EXPECT_NEAR(-side * k.spin_axis_out[0], std::sin(delta), 1e-11);  // (A.1): x . s_left = -sin(delta)
        EXPECT_LT(k.loop_residual, 1e-12);
      }
  }
  std::printf("App. A corners vs reference: largest wheel-centre difference %.2e m, spin-axis %.2e\n", worst_m,
              worst_axis);
}
