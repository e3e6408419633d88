// Table 4.1 (issue 25 item 1, docs/table_4_1.md): the chapter 4 scene as
// shipped (steer free: the seed's four degrees of freedom; s' on the upper
// arm; the spring free length held at the nominal design's) gives the seed's
// six signs of d psi / d b, by central differences and by the mixed method,
// which agree; with the steer locked (three degrees of freedom, the previous
// configuration) K and s' take the opposite signs. The options that decide it
// (upper_pivot_offset_applies_to, rest_pose) do what their keys say.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/vehicles/quarter_car.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {

// The seed's signs, b = [m1, m3, K, D, Cz, s'] (Table 4.1 as issue 25 quotes it).
const int kSeedSign[6] = {-1, 1, -1, 1, -1, 1};

SensitivityProblem table41Problem(const std::vector<Override>& overrides = {}) {
  const SceneDescription scene = SceneDescription::fromFile("scenes/ch4_sensitivity.json", standardRegistry(), overrides);
  SensitivityProblem p;
  p.model = SceneDesign::fromAnalysis(scene);
  p.parameters = {"m1", "m3", "K", "D", "Cz", "s'"};
  p.cost = CostFunctional::parse("integral_of_square:chassis.az_m_s2");
  p.t_end_s = 1.0;  // the seed's horizon: the signs are the full run's
  p.integrator.accuracy = 1e-8;  // the scene's
  return p;
}

QuarterCarParams nominalCar(const std::vector<Override>& overrides = {}) {
  BuiltScene b = SceneDescription::fromFile("scenes/ch4_sensitivity.json", standardRegistry(), overrides).build();
  return b.vehicleAs<QuarterCar>().params();
}

}  // namespace

TEST(Table41, ShippedConfigurationGivesTheSeedsSixSigns) {
  const QuarterCarParams qp = nominalCar();
  EXPECT_FALSE(qp.steer_lock);
  EXPECT_EQ(qp.upper_pivot_offset_applies_to, "arm");
  EXPECT_EQ(qp.rest_pose, "tabulated");
  {
    const QuarterCar car(qp);
    EXPECT_EQ(car.degreesOfFreedom(car.makeInitialState(false)), 4);  // the seed's "four degrees of freedom"
  }
  const SensitivityProblem p = table41Problem();
  SensitivitySettings set;
  set.tolerance = 1e-5;  // the study's (ch4_sensitivity.json "mixed")
  set.initial_intervals = 32;
  set.max_levels = 9;
  const SensitivityResult fd = makeSensitivityMethod("fd_central", set)->compute(p);
  const SensitivityResult mixed = makeSensitivityMethod("mixed", set)->compute(p);
  // The reference (ch4_sensitivity, accuracy 1e-10, Richardson over two steps),
  // measured when this configuration was chosen: m^2/s^3 per unit of b.
  const double reference[6] = {-0.0653381511, 0.0514310317, -8.33972322e-05, 0.00180581527, -1.16623448e-05,
                               15.9031113};
  for (int i = 0; i < 6; ++i) {
    const double agree = std::abs(mixed.dpsi_db[i] - fd.dpsi_db[i]) / std::abs(fd.dpsi_db[i]);
    std::printf("  %-3s fd_central %.9g mixed %.9g (rel. difference %.1e) reference %.9g\n", p.parameters[i].c_str(),
                fd.dpsi_db[i], mixed.dpsi_db[i], agree, reference[i]);
    EXPECT_EQ(fd.dpsi_db[i] < 0 ? -1 : 1, kSeedSign[i]) << p.parameters[i];
    EXPECT_EQ(mixed.dpsi_db[i] < 0 ? -1 : 1, kSeedSign[i]) << p.parameters[i];
    // Measured: fd_central and mixed differ by at most 8.0e-5 (m3); each within 7.8e-5 of the reference.
    EXPECT_LT(agree, 2e-4) << p.parameters[i];
    EXPECT_NEAR(fd.dpsi_db[i] / reference[i], 1.0, 2e-4) << p.parameters[i];
    EXPECT_NEAR(mixed.dpsi_db[i] / reference[i], 1.0, 2e-4) << p.parameters[i];
  }
  EXPECT_NEAR(fd.psi, 10.6034749, 1e-6);
  EXPECT_NEAR(mixed.psi / fd.psi, 1.0, 1e-8);  // each its own run at accuracy 1e-8: measured 1.3e-9
}

TEST(Table41, SteerLockedGivesTheOppositeSignsOfKAndSPrime) {
  // The previous configuration (3 dof): K +1.48e-4 and s' -12.0 (docs/table_4_1.md).
  SensitivityProblem p = table41Problem({{"vehicle.overrides.steer_lock", true}});
  p.parameters = {"K", "s'"};
  const SensitivityResult fd = makeSensitivityMethod("fd_central", {})->compute(p);
  std::printf("  steer locked: K %.9g s' %.9g psi %.9g\n", fd.dpsi_db[0], fd.dpsi_db[1], fd.psi);
  EXPECT_NEAR(fd.dpsi_db[0] / 1.4816e-4, 1.0, 1e-3);
  EXPECT_NEAR(fd.dpsi_db[1] / -12.0145, 1.0, 1e-3);
  EXPECT_NEAR(fd.psi, 8.17317745, 1e-6);
}

TEST(Table41, UpperPivotOffsetMovesTheArmOrTheHinge) {
  // Before the loop closes (lower arm, knuckle and upper arm at their tabulated
  // angles), s' = +0.01 m on the chassis raises the hinge and the rigid arm:
  // its ball point rises by s'; on the arm it moves the pivot up in the arm's
  // frame, so the arm (and its ball point) sits s' lower under the same hinge.
  const double s = 0.01;
  QuarterCarParams base = nominalCar();
  base.spring_free_length_from_ride_height = false;
  auto ballZ = [&](const std::string& where, double offset) {
    QuarterCarParams q = base;
    q.upper_pivot_offset_applies_to = where;
    q.upper_pivot_offset_m = offset;
    const QuarterCar car(q);
    SimTK::State st = car.getScene().getDefaultState();
    car.getScene().getSystem().realize(st, SimTK::Stage::Position);
    const SimTK::Vec3 g = car.corner().upper_arm.findStationLocationInGround(st, q.corner.upper_ball.parent_point_m);
    return car.chassis().findStationAtGroundPoint(st, g)[2];
  };
  const double z0 = ballZ("arm", 0);
  EXPECT_NEAR(ballZ("chassis", 0) - z0, 0.0, 1e-15);
  EXPECT_NEAR(ballZ("chassis", s) - z0, s, 1e-12);
  EXPECT_NEAR(ballZ("arm", s) - z0, -s, 1e-12);
}

TEST(Table41, LowerArmLevelRestPose) {
  QuarterCarParams q = nominalCar({{"vehicle.overrides.rest_pose", "lower_arm_level"}});
  EXPECT_EQ(q.rest_pose, "lower_arm_level");
  const QuarterCar car(q);
  AssemblyReport rep;
  const SimTK::State st = car.makeInitialState(false, &rep);
  const auto arm = car.corner().lower_arm;
  const double rise = arm.findStationLocationInGround(st, q.corner.lower_ball.parent_point_m)[2] -
                      arm.findStationLocationInGround(st, q.corner.lower_pivot.child_point_m)[2];
  EXPECT_NEAR(rise, 0.0, 1e-12);
  // The loop is closed: the upper ball joint's two points coincide.
  const SimTK::Vec3 a = car.corner().upper_arm.findStationLocationInGround(st, q.corner.upper_ball.parent_point_m);
  const SimTK::Vec3 b = car.corner().knuckle.findStationLocationInGround(st, q.corner.upper_ball.child_point_m);
  EXPECT_LT((a - b).norm(), 1e-9);
  // Tabulated: the loop closes with the pivot-to-ball line below level.
  QuarterCarParams t = q;
  t.rest_pose = "tabulated";
  const QuarterCar tabCar(t);
  const SimTK::State ts = tabCar.makeInitialState(false);
  const auto tarm = tabCar.corner().lower_arm;
  const double trise = tarm.findStationLocationInGround(ts, t.corner.lower_ball.parent_point_m)[2] -
                       tarm.findStationLocationInGround(ts, t.corner.lower_pivot.child_point_m)[2];
  std::printf("  tabulated rest pose: lower ball %.4f m below the pivot\n", -trise);
  EXPECT_LT(trise, -0.01);
}

TEST(Table41, UnknownReadingsAreNamed) {
  for (const char* key : {"upper_pivot_offset_applies_to", "rest_pose"}) {
    try {
      nominalCar({{std::string("vehicle.overrides.") + key, "wheel"}});
      ADD_FAILURE() << key << ": no error";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(key), std::string::npos) << m;
      EXPECT_NE(m.find("'wheel'"), std::string::npos) << m;
    }
  }
}
