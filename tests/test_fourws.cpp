// App. A 4WS vehicle builder: model size, masses, loop assembly, mirror symmetry.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "vdyn/core/simulation.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {
/// App. A's constrained (reference) model: these tests count its bodies, rows
/// and degrees of freedom and read its constrained corners (corner()), which
/// the default formulation (auto: the reduced templates) does not build.
WheeledVehicleParams appendixA() {
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a.json");
  p.formulation = "constrained";
  return p;
}
}  // namespace

TEST(FourWs, ModelSizeWithoutSteering) {
  const WheeledVehicle car(appendixA());
  const SimTK::State s = car.makeInitialState();
  // Joint coordinates (seed 3.2): chassis 6 + 4 x (lower arm 1 + knuckle 3 + upper
  // arm 1 + spin 1) = 30 mobilities; 12 loop-closure equations. The four steering
  // constraints (a plugin) bring the 18 degrees of freedom down to the seed's 14.
  EXPECT_EQ(s.getNU(), 30);
  EXPECT_EQ(s.getNUDotErr(), 12);
  EXPECT_EQ(car.degreesOfFreedom(s), 18);
}

TEST(FourWs, TotalMassIsTableA1) {
  const WheeledVehicle car(appendixA());
  // 800 + 2 (0.5 + 5 + 0.5 + 20) + 2 (0.5 + 5 + 0.5 + 30) = 924 kg (docs/vehicle_data.md).
  EXPECT_DOUBLE_EQ(car.totalMass(), 924.0);
}

TEST(FourWs, AssemblyClosesAllFourLoops) {
  const WheeledVehicle car(appendixA());
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
  const WheeledVehicle car(appendixA());
  const SimTK::State s = car.makeInitialState();
  for (int right : {RF, RR}) {
    const int left = right + 1;
    const SimTK::MobilizedBody bodies[2][4] = {
        {car.corner(right).lower_arm, car.corner(right).knuckle, car.corner(right).upper_arm, car.corner(right).wheel},
        {car.corner(left).lower_arm, car.corner(left).knuckle, car.corner(left).upper_arm, car.corner(left).wheel}};
    for (int b = 0; b < 4; ++b) {
      const SimTK::Vec3 pr = bodies[0][b].getBodyOriginLocation(s), pl = bodies[1][b].getBodyOriginLocation(s);
      EXPECT_NEAR(pr[0], pl[0], 1e-9) << car.cornerName(right) << " body " << b;
      EXPECT_NEAR(pr[1], -pl[1], 1e-9) << car.cornerName(right) << " body " << b;
      EXPECT_NEAR(pr[2], pl[2], 1e-9) << car.cornerName(right) << " body " << b;
    }
  }
}

TEST(FourWs, InitialSpeedRollsTheWheels) {
  const WheeledVehicle car(appendixA());
  const SimTK::State s = car.makeInitialState(10.0);
  const Scene& sc = car.getScene();
  EXPECT_NEAR(sc.evalOutput("chassis.forward_speed_m_s", s), 10.0, 1e-12);
  EXPECT_NEAR(sc.evalOutput("chassis.side_slip_rad", s), 0.0, 1e-12);
  for (int c = 0; c < 4; ++c) {
    const TireContact k = car.tire(c).calcContact(s);
    ASSERT_TRUE(k.in_contact) << car.cornerName(c);
    // Free rolling: no longitudinal slip velocity, so no longitudinal force.
    EXPECT_NEAR(k.forces.slip_ratio, 0.0, 1e-9) << car.cornerName(c);
  }
}

TEST(FourWs, UnknownTirePluginListsKnownOnes) {
  WheeledVehicleParams p = appendixA();
  p.axles[0].tire.plugin = "magic";
  try {
    WheeledVehicle car(p);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "appendix_a.json: tire.plugin: unknown force element plugin 'magic'; known: body_force, fiala, gim, "
                           "linear, magic_formula; no force element library registers it: load the one that does with "
                           "--plugin LIB.so or the scene's \"plugin_libraries\"");
  }
}

// --- steering (App. A (A.1)-(A.4)) ------------------------------------------

namespace {
/// The 4WS vehicle with front and rear steering commands, run to t_end at
/// 10 m/s; records the chassis and steering outputs every 10 ms.
struct SteeredRun {
  std::unique_ptr<WheeledVehicle> car;
  std::unique_ptr<Recorder> rec;
  RunSummary run;
  SimTK::State final;
};

SteeredRun runSteered(std::shared_ptr<const SteeringCommand> front, std::shared_ptr<const SteeringCommand> rear,
                      double tEnd) {
  SteeredRun r;
  r.car = std::make_unique<WheeledVehicle>(appendixA());
  r.car->addAxleSteering("front_steer", "front", std::move(front));
  r.car->addAxleSteering("rear_steer", "rear", std::move(rear));
  r.final = r.car->makeInitialState(10.0);
  r.rec = std::make_unique<Recorder>(
      r.car->getScene(), std::vector<std::string>{"chassis.y_m", "chassis.yaw_rate_rad_s", "front_steer.angle_rad",
                                                  "front_steer.command_rad", "rear_steer.angle_rad",
                                                  "rear_steer.command_rad", "rf.spin_rad_s", "lf.spin_rad_s",
                                                  "rr.spin_rad_s", "lr.spin_rad_s"});
  SimulationSettings sim;
  sim.t_end_s = tEnd;
  sim.report_interval_s = 0.01;
  sim.integrator.accuracy = 1e-7;
  r.run = simulate(r.car->getScene(), r.final, sim, r.rec.get());
  return r;
}

double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}
}  // namespace

TEST(FourWsSteering, FourteenDegreesOfFreedom) {
  WheeledVehicle car(appendixA());
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0));
  const SimTK::State s = car.makeInitialState(10.0);
  EXPECT_EQ(s.getNUDotErr(), 16);  // 12 loop closure + 4 steering (App. A)
  EXPECT_EQ(car.degreesOfFreedom(s), 14);
}

TEST(FourWsSteering, StraightRunStaysStraightAndSymmetric) {
  const SteeredRun r = runSteered(std::make_shared<HoldCommand>(0.0), std::make_shared<HoldCommand>(0.0), 1.0);
  const auto& y = r.rec->column("chassis.y_m");
  double drift = 0;
  for (double v : y) drift = std::max(drift, std::abs(v));
  EXPECT_LE(drift, 1e-6);
  // Left and right wheels of each axle spin alike (mirror-symmetric model).
  EXPECT_LE(maxAbsDiff(r.rec->column("rf.spin_rad_s"), r.rec->column("lf.spin_rad_s")), 1e-9 * 34);
  EXPECT_LE(maxAbsDiff(r.rec->column("rr.spin_rad_s"), r.rec->column("lr.spin_rad_s")), 1e-9 * 34);
  EXPECT_LE(r.run.max_constraint_error, 1e-8);
}

TEST(FourWsSteering, AngleFollowsTheSmoothStepCommand) {
  const double d = 4.0 * SimTK::Pi / 180;
  const SteeredRun r = runSteered(std::make_shared<SmoothStepCommand>(0, d, 0.5, 1.0),
                                  std::make_shared<SmoothStepCommand>(0, d / 4, 0.5, 1.0), 2.0);
  EXPECT_LE(maxAbsDiff(r.rec->column("front_steer.angle_rad"), r.rec->column("front_steer.command_rad")), 1e-6);
  EXPECT_LE(maxAbsDiff(r.rec->column("rear_steer.angle_rad"), r.rec->column("rear_steer.command_rad")), 1e-6);
  EXPECT_NEAR(r.rec->column("front_steer.angle_rad").back(), d, 1e-6);
  EXPECT_GT(r.rec->column("chassis.yaw_rate_rad_s").back(), 0.1);  // steering left turns left
  EXPECT_LE(r.run.max_constraint_error, 1e-8);
}

TEST(FourWsSteering, OppositeStepsGiveMirroredYawRates) {
  const double d = 2.0 * SimTK::Pi / 180;
  const SteeredRun left = runSteered(std::make_shared<SmoothStepCommand>(0, d, 0.2, 0.5),
                                     std::make_shared<HoldCommand>(0.0), 1.2);
  const SteeredRun right = runSteered(std::make_shared<SmoothStepCommand>(0, -d, 0.2, 0.5),
                                      std::make_shared<HoldCommand>(0.0), 1.2);
  const auto& rl = left.rec->column("chassis.yaw_rate_rad_s");
  const auto& rr = right.rec->column("chassis.yaw_rate_rad_s");
  double peak = 0, asym = 0;
  for (std::size_t i = 0; i < rl.size(); ++i) {
    peak = std::max(peak, std::abs(rl[i]));
    asym = std::max(asym, std::abs(rl[i] + rr[i]));
  }
  EXPECT_GT(peak, 0.05);
  EXPECT_LE(asym, 1e-8 * peak);
}

TEST(FourWsSteering, CommandErrorsAreNamed) {
  const auto cmd = [](const Json& j) { return makeSteeringCommand(ParamReader::fromJson(j, "scene.json steering")); };
  try {
    cmd(Json{{"type", "zigzag"}});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "scene.json steering: type: unknown steering command 'zigzag'; known: chirp, hold, ramp, "
                           "sine, sine_with_dwell, smooth_step, steps, table");
  }
  try {
    cmd(Json{{"type", "smooth_step"}, {"final_rad", 0.1}, {"start_time_s", 0.5}, {"duration_s", -1.0}});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "steering duration_s must be positive, got -1");
  }
}

// --- speed hold (3.18) --------------------------------------------------------

TEST(FourWsSpeedHold, HoldsTheSpeedThroughATurnAndReportsItsForce) {
  WheeledVehicle car(appendixA());
  const double d = 4.0 * SimTK::Pi / 180;
  car.addAxleSteering("front_steer", "front", std::make_shared<SmoothStepCommand>(0, d, 0.2, 0.5));
  car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0));
  car.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0));
  SimTK::State s = car.makeInitialState(10.0);
  EXPECT_EQ(car.degreesOfFreedom(s), 13);  // 14 less the speed condition
  SimulationSettings sim;
  sim.t_end_s = 2.0;
  sim.report_interval_s = 0.05;
  sim.integrator.accuracy = 1e-7;
  Recorder rec(car.getScene(), {"chassis.forward_speed_m_s", "chassis.lateral_speed_m_s", "speed_hold.force_N"});
  simulate(car.getScene(), s, sim, &rec);
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const double vx = rec.column("chassis.forward_speed_m_s")[i], vy = rec.column("chassis.lateral_speed_m_s")[i];
    EXPECT_NEAR(std::hypot(vx, vy), 10.0, 1e-7) << "t = " << rec.time()[i];
  }
  // Cornering drag of the tires needs a propulsive force (rolling resistance is 0).
  EXPECT_GT(rec.column("speed_hold.force_N").back(), 10.0);
}

TEST(FourWsSpeedHold, RejectsANonPositiveSpeed) {
  try {
    SpeedHoldPlugin p("speed_hold", "chassis", -3.0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "speed hold speed_m_s must be positive, got -3");
  }
}
