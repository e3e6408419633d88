// App. A 4WS vehicle builder: model size, masses, loop assembly, mirror symmetry.
#include <gtest/gtest.h>

#include "vdyn/core/simulation.h"
#include "vdyn/vehicles/fourws.h"

using namespace vdyn;

namespace {
FourWsParams appendixA() { return FourWsParams::fromFile("appendix_a.json"); }
}  // namespace

TEST(FourWs, ModelSizeWithoutSteering) {
  const FourWsVehicle car(appendixA());
  const SimTK::State s = car.makeInitialState();
  // Joint coordinates (seed 3.2): chassis 6 + 4 x (lower arm 1 + knuckle 3 + upper
  // arm 1 + spin 1) = 30 mobilities; 12 loop-closure equations. The four steering
  // constraints (a plugin) bring the 18 degrees of freedom down to the seed's 14.
  EXPECT_EQ(s.getNU(), 30);
  EXPECT_EQ(s.getNUDotErr(), 12);
  EXPECT_EQ(car.degreesOfFreedom(s), 18);
}

TEST(FourWs, TotalMassIsTableA1) {
  const FourWsVehicle car(appendixA());
  // 800 + 2 (0.5 + 5 + 0.5 + 20) + 2 (0.5 + 5 + 0.5 + 30) = 924 kg (DESIGN.md section 9).
  EXPECT_DOUBLE_EQ(car.totalMass(), 924.0);
}

TEST(FourWs, AssemblyClosesAllFourLoops) {
  const FourWsVehicle car(appendixA());
  AssemblyReport rep;
  const SimTK::State s = car.makeInitialState(0.0, &rep);
  EXPECT_NEAR(rep.initial_loop_gap_m, 0.040, 0.002);  // the front loops, as printed
  EXPECT_LT(positionConstraintError(s), 1e-10);
  EXPECT_LT(rep.max_move_m, 0.05);
  double rearMove = 0;
  for (const auto& [name, d] : rep.body_moves_m)
    if (name.rfind("r", 0) == 0 && name[1] == 'r') rearMove = std::max(rearMove, d);
  EXPECT_LT(rearMove, 0.005);  // the rear loops are open by only about 1 mm
}

TEST(FourWs, LeftSideMirrorsRightAfterAssembly) {
  const FourWsVehicle car(appendixA());
  const SimTK::State s = car.makeInitialState();
  for (int right : {RF, RR}) {
    const int left = right + 1;
    const SimTK::MobilizedBody bodies[2][4] = {
        {car.corner(right).lower_arm, car.corner(right).knuckle, car.corner(right).upper_arm, car.corner(right).wheel},
        {car.corner(left).lower_arm, car.corner(left).knuckle, car.corner(left).upper_arm, car.corner(left).wheel}};
    for (int b = 0; b < 4; ++b) {
      const SimTK::Vec3 pr = bodies[0][b].getBodyOriginLocation(s), pl = bodies[1][b].getBodyOriginLocation(s);
      EXPECT_NEAR(pr[0], pl[0], 1e-9) << cornerName(right) << " body " << b;
      EXPECT_NEAR(pr[1], -pl[1], 1e-9) << cornerName(right) << " body " << b;
      EXPECT_NEAR(pr[2], pl[2], 1e-9) << cornerName(right) << " body " << b;
    }
  }
}

TEST(FourWs, InitialSpeedRollsTheWheels) {
  const FourWsVehicle car(appendixA());
  const SimTK::State s = car.makeInitialState(10.0);
  const Scene& sc = car.getScene();
  EXPECT_NEAR(sc.evalOutput("chassis.forward_speed_m_s", s), 10.0, 1e-12);
  EXPECT_NEAR(sc.evalOutput("chassis.side_slip_rad", s), 0.0, 1e-12);
  for (int c = 0; c < 4; ++c) {
    const TireContact k = car.tire(c).calcContact(s);
    ASSERT_TRUE(k.in_contact) << cornerName(c);
    // Free rolling: no longitudinal slip velocity, so no longitudinal force.
    EXPECT_NEAR(k.forces.slip_ratio, 0.0, 1e-9) << cornerName(c);
  }
}

TEST(FourWs, UnknownTirePluginListsKnownOnes) {
  FourWsParams p = appendixA();
  p.tire_plugin = "magic";
  try {
    FourWsVehicle car(p);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "4ws tire plugin: unknown force element plugin 'magic'; known: fiala, gim, linear");
  }
}
