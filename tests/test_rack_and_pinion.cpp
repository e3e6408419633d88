// The rack-and-pinion steering template (vehicles/templates/rack_and_pinion)
// and a steering plugin driving it through tie rods:
// (a) the rack's kinematics (both wheels' steer angles and the overall ratio
//     d(pinion)/d(mean road-wheel angle)) against the independent kinematics
//     reference (tests/reference: loops closed by Newton on the hardpoints),
//     on the BMW E90's front MacPherson strut with Chrono's rack (c = -0.1
//     m/rad, +-64 deg of pinion; docs/bmw_e90.md) and on the E90's rear
//     double wishbone with its tie rods moved onto a rack;
// (b) a time-commanded run: the rack follows k * command(t), the mean
//     road-wheel angle the commanded road-wheel angle;
// (c) state-driven runs: under a law with a closed-form solution, and the
//     path controller through a lane change (SteeringActuator unchanged);
// (d) bad data named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "reference/suspension_kinematics.h"
#include "test_util.h"
#include "vdyn/core/recorder.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/path_control/path_control.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/core/simulation.h"
#include "vdyn/templates/macpherson_strut.h"
#include "vdyn/templates/rack_and_pinion.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;
namespace kr = vdyn::kinematics_reference;

namespace {

const double kDeg = SimTK::Pi / 180;
// Chrono's E90 rack (BMW_E90_Steering.cpp, docs/bmw_e90.md): pinion radius
// 0.1 m/rad, signed -0.1 (the tie rods behind the axle), 64 deg of pinion.
constexpr double kC = -0.1;
constexpr double kMaxPinion = 1.117010721276371;

kr::Vec3 arr(const Json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

Json hardpointsFile() { return readJsonFile(std::string(VDYN_TEST_DATA_DIR) + "/bmw_e90_hardpoints.json"); }

Json rackBlock() {
  return {{"template", "rack_and_pinion"},
          {"rack_travel_per_pinion_rad_m", kC},
          {"rack_mass_kg", 9.072},
          {"rack_inertia_kg_m2", 1.0},
          {"location_m", {-0.2, 0.0, -0.05}},
          {"rack_travel_limit_m", 0.1 * kMaxPinion}};
}

/// vehicles/data/bmw_e90.json with its front struts' tie rods on Chrono's
/// rack (TIEROD_C, TIEROD_U of tests/data/bmw_e90_hardpoints.json).
Json e90RackData() {
  Json d = ParamReader::fromFile("bmw_e90.json").json();
  const Json h = hardpointsFile().at("front").at("hardpoints_m");
  Json& s = d["axles"]["front"]["suspension"];
  s["tie_rod"] = "rack";
  s["hardpoints_m"]["tierod_chassis"] = h.at("TIEROD_C");
  s["hardpoints_m"]["tierod_upright"] = h.at("TIEROD_U");
  d["axles"]["front"]["steering"] = rackBlock();
  return d;
}

WheeledVehicleParams paramsOf(const Json& d) { return WheeledVehicleParams::fromParams(ParamReader::fromJson(d, "e90_rack")); }

kr::MacPhersonHardpoints strutReference(const Json& block) {
  const Json& h = block.at("hardpoints_m");
  kr::MacPhersonHardpoints hp;
  hp.spindle = arr(h.at("spindle"));
  hp.lca_f = arr(h.at("lca_front"));
  hp.lca_b = arr(h.at("lca_back"));
  hp.lca_u = arr(h.at("lca_upright"));
  hp.strut_c = arr(h.at("strut_chassis"));
  hp.strut_u = arr(h.at("strut_upright"));
  hp.tierod_c = arr(h.at("tierod_chassis"));
  hp.tierod_u = arr(h.at("tierod_upright"));
  hp.camber_rad = block.at("camber_rad").get<double>();
  hp.toe_in_rad = block.value("toe_in_rad", 0.0);
  return hp;
}

kr::DoubleWishboneHardpoints wishboneReference(const Json& block) {
  const Json& h = block.at("hardpoints_m");
  kr::DoubleWishboneHardpoints hp;
  hp.spindle = arr(h.at("spindle"));
  hp.uca_f = arr(h.at("uca_front"));
  hp.uca_b = arr(h.at("uca_back"));
  hp.uca_u = arr(h.at("uca_upright"));
  hp.lca_f = arr(h.at("lca_front"));
  hp.lca_b = arr(h.at("lca_back"));
  hp.lca_u = arr(h.at("lca_upright"));
  hp.tierod_c = arr(h.at("tierod_chassis"));
  hp.tierod_u = arr(h.at("tierod_upright"));
  hp.camber_rad = block.value("camber_rad", 0.0);
  hp.toe_in_rad = block.value("toe_in_rad", 0.0);
  return hp;
}

struct Sweep {
  double worstAngle = 0, worstRatio = 0, ratioAtCentre = 0;
  int poses = 0;
};

/// The rig of `block` on the rack against `reference(pinion)` over
/// |pinion| <= maxPinion in steps of `step` (outward from centre, both ways).
template <class Ref>
Sweep sweep(const Json& block, double maxPinion, double step, const Ref& reference) {
  Sweep w;
  const RackAndPinionParams rp = RackAndPinionParams::fields().read(ParamReader::fromJson(rackBlock(), "rack"));
  for (double dir : {1.0, -1.0}) {
    RackSteeringRig rig(block, "suspension", rp, vehiclePlugins());
    for (double pinion = 0; pinion <= maxPinion + 1e-12; pinion += step) {
      const double th = dir * pinion;
      const RackSteerPose m = rig.solve(kC * th);
      const kr::RackSteer r = reference(th);
      EXPECT_LT(m.loop_error, 1e-10) << "pinion " << th;
      EXPECT_NEAR(m.rack_travel_m, r.rack_travel_m, 1e-15);
      EXPECT_NEAR(m.steer_right_rad, r.steer_right_rad, 1e-6) << "pinion " << th;
      EXPECT_NEAR(m.steer_left_rad, r.steer_left_rad, 1e-6) << "pinion " << th;
      EXPECT_NEAR(m.overall_ratio / r.overall_ratio, 1.0, 1e-6) << "pinion " << th;
      w.worstAngle = std::max({w.worstAngle, std::abs(m.steer_right_rad - r.steer_right_rad),
                               std::abs(m.steer_left_rad - r.steer_left_rad)});
      w.worstRatio = std::max(w.worstRatio, std::abs(m.overall_ratio / r.overall_ratio - 1));
      if (pinion == 0) w.ratioAtCentre = m.overall_ratio;
      ++w.poses;
    }
  }
  return w;
}

}  // namespace

TEST(RackAndPinion, StrutRackKinematicsMatchTheIndependentReferenceOverTheRackTravel) {
  const Json block = e90RackData()["axles"]["front"]["suspension"];
  const kr::MacPhersonHardpoints hp = strutReference(block);
  const Sweep w = sweep(block, kMaxPinion, 4 * kDeg, [&](double th) { return kr::rackSteer(hp, th, kC); });
  EXPECT_EQ(w.poses, 2 * 17);
  // docs/bmw_e90.md's table: 2.0857 at centre.
  EXPECT_NEAR(w.ratioAtCentre, 2.0857, 5e-5);
  // At full lock (64 deg, rack -111.7 mm): left 43.5443, right 29.9180 deg.
  const kr::RackSteer lock = kr::rackSteer(hp, kMaxPinion, kC);
  EXPECT_NEAR(lock.steer_left_rad / kDeg, 43.5443, 1e-4);
  EXPECT_NEAR(lock.steer_right_rad / kDeg, 29.9180, 1e-4);
  std::printf("E90 strut rack vs reference, pinion +-64 deg (%d poses): angles %.2e rad, ratio %.2e relative; "
              "N0 = %.9f\n",
              w.poses, w.worstAngle, w.worstRatio, w.ratioAtCentre);
}

TEST(RackAndPinion, WishboneRackKinematicsMatchTheIndependentReferenceOverTheRackTravel) {
  // The E90's rear double wishbone (hardpoint form) with its tie rods on the rack.
  Json block = ParamReader::fromFile("bmw_e90.json").json()["axles"]["rear"]["suspension"];
  block["tie_rod"] = "rack";
  const kr::DoubleWishboneHardpoints hp = wishboneReference(block);
  const double maxPinion = 24 * kDeg;  // rack +-41.9 mm
  const Sweep w = sweep(block, maxPinion, 4 * kDeg, [&](double th) { return kr::rackSteer(hp, th, kC); });
  EXPECT_EQ(w.poses, 2 * 7);
  std::printf("E90 rear wishbone rack vs reference, pinion +-24 deg (%d poses): angles %.2e rad, ratio %.2e "
              "relative; N0 = %.9f\n",
              w.poses, w.worstAngle, w.worstRatio, w.ratioAtCentre);
}

TEST(RackAndPinion, VehicleBuildsTheRackWithItsRatioAndKeepsTheDegreesOfFreedom) {
  const Json d = e90RackData();
  WheeledVehicle car(paramsOf(d));
  const int front = car.axleIndex("front");
  ASSERT_NE(car.rack(front), nullptr);
  EXPECT_EQ(car.rack(car.axleIndex("rear")), nullptr);
  const kr::RackSteer ref = kr::rackSteer(strutReference(d["axles"]["front"]["suspension"]), 0.0, kC);
  EXPECT_NEAR(car.overallSteeringRatio(front) / ref.overall_ratio, 1.0, 1e-6);
  EXPECT_TRUE(car.getScene().hasBody("front.rack"));
  // Chassis 6 + 4 wheel travels + 4 wheel spins + rack 1 - its command 1 =
  // 14, as the same car steered at the knuckles ((A.1), no tie rods).
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  const SimTK::State s = car.makeInitialState(0.0);
  EXPECT_EQ(car.degreesOfFreedom(s), 14);
  // The rack's 9.072 kg adds to the car's mass.
  EXPECT_NEAR(car.totalMass() - WheeledVehicle(WheeledVehicleParams::fromFile("bmw_e90.json")).totalMass(), 9.072,
              1e-12);
}

namespace {
struct TimedRun {
  double N0 = 0;
  RunSummary run;
  std::vector<double> t, cmd, mean, x, sw, rf, lf;
};
/// The E90 on its rack at 10 m/s for 0.6 s under a road-wheel command, its
/// chassis moving straight at the tabulated height (locked at the velocity
/// level, as on a kinematics-and-compliance rig: the E90's data does not start
/// in equilibrium and would rise on its front springs, and its tie rods' bump
/// steer would change the ratio with that travel).
TimedRun runTimed(std::shared_ptr<const SteeringCommand> command) {
  TimedRun r;
  WheeledVehicle car(paramsOf(e90RackData()));
  r.N0 = car.overallSteeringRatio(car.axleIndex("front"));
  car.addAxleSteering("front_steer", "front", std::move(command));
  SimTK::State s = car.makeInitialState(10.0);
  car.chassis().lock(s, SimTK::Motion::Velocity);
  Recorder rec(car.getScene(), {"front_steer.command_rad", "front_steer.angle_rad", "front_steer.rack_travel_m",
                                "front_steer.steering_wheel_rad", "front_steer.rf_angle_rad",
                                "front_steer.lf_angle_rad"});
  SimulationSettings sim;
  sim.t_end_s = 0.6;
  sim.report_interval_s = 0.01;
  sim.integrator.accuracy = 1e-7;
  r.run = simulate(car.getScene(), s, sim, &rec);
  r.t = rec.time();
  r.cmd = rec.column("front_steer.command_rad");
  r.mean = rec.column("front_steer.angle_rad");
  r.x = rec.column("front_steer.rack_travel_m");
  r.sw = rec.column("front_steer.steering_wheel_rad");
  r.rf = rec.column("front_steer.rf_angle_rad");
  r.lf = rec.column("front_steer.lf_angle_rad");
  return r;
}
}  // namespace

TEST(RackAndPinion, TimeCommandedRackFollowsTheCommandAndTheWheelsTheRoadWheelAngle) {
  const double step = 0.01;  // road-wheel angle, rad
  const TimedRun r = runTimed(std::make_shared<SmoothStepCommand>(0.0, step, 0.1, 0.3));
  // The same car with the rack held at centre.
  const TimedRun h = runTimed(std::make_shared<HoldCommand>(0.0));
  ASSERT_EQ(r.t.size(), h.t.size());
  const double k = kC * r.N0;
  double rackErr = 0, swErr = 0, meanErr = 0, holdMean = 0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    rackErr = std::max(rackErr, std::abs(r.x[i] - k * r.cmd[i]));
    swErr = std::max(swErr, std::abs(r.sw[i] - r.x[i] / kC));
    meanErr = std::max(meanErr, std::abs(r.mean[i] - 0.5 * (r.rf[i] + r.lf[i])));
    holdMean = std::max(holdMean, std::abs(h.mean[i]));
  }
  EXPECT_LT(rackErr, 1e-8);  // the constraint x - k q(t), projected at every step
  EXPECT_LT(swErr, 1e-15);
  EXPECT_LT(meanErr, 1e-15);
  // Held at centre the symmetric car keeps a zero mean angle (toe is
  // symmetric; the tires' lateral forces move the wheels by micrometres).
  EXPECT_LT(holdMean, 1e-6);
  // The mean road-wheel angle follows the command to first order in the rack
  // travel (linear in N0): the kinematics reference at the same pinion angle
  // N0 * 0.01 rad (design wheel travel) gives the mean to second order; the
  // run differs by the wheel travel the tire forces bring (< 1 %).
  const double dMean = r.mean.back() - h.mean.back();
  const double refMean = kr::rackSteer(strutReference(e90RackData()["axles"]["front"]["suspension"]), r.N0 * step, kC)
                             .steer_mean_rad;
  EXPECT_NEAR(refMean / step, 1.0, 1e-3);  // second order in 0.01 rad
  EXPECT_NEAR(dMean / step, 1.0, 0.01);
  const double dLeft = r.lf.back() - h.lf.back(), dRight = r.rf.back() - h.rf.back();
  std::printf("rack run: N0 %.6f, max |x - c N0 q| %.2e m (run's max constraint error %.2e), mean angle %.6f for "
              "%.6f rad (reference %.6f; right %.6f, left %.6f; held: mean %.1e)\n",
              r.N0, rackErr, r.run.max_constraint_error, dMean, step, refMean, dRight, dLeft, holdMean);
}

TEST(RackAndPinion, SteeringWheelCommandUnitsGiveTheRackTravelCTimesTheAngle) {
  WheeledVehicle car(paramsOf(e90RackData()));
  const double theta = 0.3;  // steering-wheel angle, rad
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(theta), "steering_wheel");
  const SimTK::State s = car.makeInitialState(0.0);
  EXPECT_NEAR(car.getScene().evalOutput("front_steer.rack_travel_m", s), kC * theta, 1e-10);
  EXPECT_NEAR(car.getScene().evalOutput("front_steer.steering_wheel_rad", s), theta, 1e-9);
}

namespace {
/// q'' = w^2 (qT - q) - 2 w q' (critically damped): from q = q' = 0,
/// q(t) = qT (1 - (1 + w t) e^{-w t}).
class ApproachLaw : public SteeringLaw {
 public:
  ApproachLaw(const SteeringActuator& st, double target, double w)
      : SteeringLaw("approach"), st_(st), target_(target), w_(w) {}

 protected:
  double DoCalcAcceleration(const SimTK::State& s) const override {
    return w_ * w_ * (target_ - st_.getAngle(s)) - 2 * w_ * st_.getRate(s);
  }

 private:
  const SteeringActuator& st_;
  double target_, w_;
};
}  // namespace

TEST(RackAndPinion, StateDrivenRackFollowsItsLaw) {
  WheeledVehicle car(paramsOf(e90RackData()));
  const double N0 = car.overallSteeringRatio(car.axleIndex("front"));
  SteeringPlugin& st = car.addAxleSteering("front_steer", "front", SteeringStateSpec{});
  const SteeringActuator& act = st;
  const double target = 0.01, w = 10;
  st.setAccelerationLaw(std::make_shared<ApproachLaw>(act, target, w));
  Scene& sc = car.updScene();
  SimTK::State s = car.makeInitialState(10.0);
  // The state is the rack's coordinate (no steer body).
  ASSERT_EQ(steeringStateBodies(sc).size(), 1u);
  EXPECT_EQ(steeringStateBodies(sc)[0], sc.getBody("front.rack").getMobilizedBodyIndex());
  EXPECT_FALSE(sc.hasBody("front_steer.steer"));
  EXPECT_EQ(car.degreesOfFreedom(s), 14);  // the rack moves by its law, the tie rods steer the wheels
  SimulationSettings sim;
  sim.t_end_s = 0.6;
  sim.report_interval_s = 0.01;
  sim.integrator.accuracy = 1e-8;
  Recorder rec(sc, {"front_steer.command_rad", "front_steer.rack_travel_m", "front_steer.angle_rad"});
  simulate(sc, s, sim, &rec);
  const auto& q = rec.column("front_steer.command_rad");
  const auto& x = rec.column("front_steer.rack_travel_m");
  double lawErr = 0, kErr = 0;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const double t = rec.time()[i];
    lawErr = std::max(lawErr, std::abs(q[i] - target * (1 - (1 + w * t) * std::exp(-w * t))));
    kErr = std::max(kErr, std::abs(x[i] - kC * N0 * q[i]));
  }
  EXPECT_LT(lawErr, 1e-7);  // integrated against the closed form
  EXPECT_LT(kErr, 1e-15);   // x = c N0 q: getAngle() is the rack's coordinate over c N0
  std::printf("state-driven rack: max |q - closed form| %.2e rad, q(0.6 s) %.6f, rack %.6f m\n", lawErr, q.back(),
              x.back());
}

TEST(RackAndPinion, BadDataIsNamed) {
  // tie_rod "rack" without a steering block.
  Json d = e90RackData();
  d["axles"]["front"].erase("steering");
  EXPECT_NE(test::errorOf([&] { paramsOf(d); })
                .find("e90_rack: axles.front.suspension.tie_rod: \"rack\" needs the axle to have a \"steering\""),
            std::string::npos)
      << test::errorOf([&] { paramsOf(d); });
  // A rack under a suspension whose tie rods are on the chassis.
  d = e90RackData();
  d["axles"]["front"]["suspension"]["tie_rod"] = "chassis";
  EXPECT_NE(test::errorOf([&] { paramsOf(d); })
                .find("e90_rack: axles.front.steering: a rack needs the axle's suspension to have \"tie_rod\": \"rack\""),
            std::string::npos)
      << test::errorOf([&] { paramsOf(d); });
  // c = 0, a missing mass, an unknown template, an unknown key.
  d = e90RackData();
  d["axles"]["front"]["steering"]["rack_travel_per_pinion_rad_m"] = 0.0;
  EXPECT_NE(test::errorOf([&] { paramsOf(d); }).find("rack_travel_per_pinion_rad_m must be a finite non-zero number"),
            std::string::npos);
  d = e90RackData();
  d["axles"]["front"]["steering"].erase("rack_mass_kg");
  EXPECT_NE(test::errorOf([&] { paramsOf(d); }).find("rack_mass_kg"), std::string::npos);
  d = e90RackData();
  d["axles"]["front"]["steering"]["template"] = "rack_pinion";
  EXPECT_NE(test::errorOf([&] { paramsOf(d); }).find("unknown steering template 'rack_pinion'"), std::string::npos)
      << test::errorOf([&] { paramsOf(d); });
  d = e90RackData();
  d["axles"]["front"]["steering"]["pinion_radius_m"] = 0.1;
  EXPECT_NE(test::errorOf([&] { paramsOf(d); }).find("pinion_radius_m"), std::string::npos);
  // tie_rod spelled wrong.
  d = e90RackData();
  d["axles"]["front"]["suspension"]["tie_rod"] = "racks";
  EXPECT_NE(test::errorOf([&] { paramsOf(d); }).find("tie_rod must be \"none\", \"chassis\" or \"rack\", got \"racks\""),
            std::string::npos)
      << test::errorOf([&] { paramsOf(d); });
  // A steering plugin on the rear (tie rods on the chassis, no rack): named as today.
  WheeledVehicle car(paramsOf(e90RackData()));
  EXPECT_EQ(test::errorOf([&] { car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0)); }),
            "vehicle: steering plugin 'rear_steer' steers axle 'rear', whose knuckles its suspension's tie rods hold "
            "(tie_rod \"chassis\") and which has no rack");
  // Command units other than the two.
  EXPECT_NE(test::errorOf([&] {
              car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0), "degrees");
            }).find("command_angle must be \"road_wheel\" or \"steering_wheel\", got \"degrees\""),
            std::string::npos);
  // A command beyond the rack's travel: 0.5 rad of road wheel is about 0.104 m
  // of rack... 0.6 rad asks more than the 0.1117 m limit.
  WheeledVehicle car2(paramsOf(e90RackData()));
  EXPECT_NE(test::errorOf([&] {
              car2.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.6));
            }).find("beyond rack_travel_limit_m 0.1117"),
            std::string::npos);
}


// The scene-file path: a "steering" plugin attached to the rack axle drives
// the rack (vehicles/data/scenes/e90_rack_step_steer.json on bmw_e90_rack.json).
TEST(RackAndPinion, SceneSteeringAttachedToTheRackAxleDrivesTheRack) {
  // The shipped data file is the test's E90 on the rack.
  const WheeledVehicle shipped(WheeledVehicleParams::fromFile("bmw_e90_rack.json"));
  const WheeledVehicle here(paramsOf(e90RackData()));
  const double N0 = shipped.overallSteeringRatio(0);
  EXPECT_EQ(N0, here.overallSteeringRatio(0));
  EXPECT_EQ(shipped.totalMass(), here.totalMass());
  const SceneDescription scene = SceneDescription::fromFile("scenes/e90_rack_step_steer.json", standardRegistry());
  const Json summary = runScene(scene);
  const Json& f = summary["final"];
  const double step = 0.017453292519943295;  // 1 deg road-wheel angle
  EXPECT_DOUBLE_EQ(f["front_steer.command_rad"].get<double>(), step);
  EXPECT_NEAR(f["front_steer.rack_travel_m"].get<double>(), kC * N0 * step, 1e-8);
  EXPECT_NEAR(f["front_steer.steering_wheel_rad"].get<double>(), N0 * step, 1e-7);
  EXPECT_GT(f["chassis.yaw_rate_rad_s"].get<double>(), 0.01);  // a left turn
  EXPECT_EQ(summary["vehicle"]["dof"].get<int>(), 14 - 1);  // the speed hold's row
  std::printf("scene on the rack: rack %.6f m, steering wheel %.6f rad, mean road wheel %.6f rad, yaw rate %.5f "
              "rad/s\n",
              f["front_steer.rack_travel_m"].get<double>(), f["front_steer.steering_wheel_rad"].get<double>(),
              f["front_steer.angle_rad"].get<double>(), f["chassis.yaw_rate_rad_s"].get<double>());
  // Steering-wheel units by the plugin's option: 0.3 rad of steering wheel.
  const SceneDescription sw = scene.withOverrides({{"plugins.front_steer.command_angle", "steering_wheel"},
                                                   {"plugins.front_steer.command.final_rad", 0.3},
                                                   {"analysis.t_end_s", 1.2}});
  const Json s2 = runScene(sw);
  EXPECT_NEAR(s2["final"]["front_steer.rack_travel_m"].get<double>(), kC * 0.3, 1e-8);
  // command_angle on an axle without a rack is named.
  Json bad = scene.json();
  bad["vehicle"]["data"] = "appendix_a.json";
  bad["plugins"][0]["command_angle"] = "steering_wheel";
  EXPECT_NE(test::errorOf([&] { SceneDescription::fromJson(bad, "bad.json", standardRegistry()).build(); })
                .find("command_angle: only a steering on a rack axle"),
            std::string::npos)
      << test::errorOf([&] { SceneDescription::fromJson(bad, "bad.json", standardRegistry()).build(); });
}

// The path controller (chapter 7's lane-change gains) through SteeringActuator
// on the rack: the E90 changes lane.
TEST(RackAndPinion, PathControllerSteersTheRackThroughALaneChange) {
  WheeledVehicle car(paramsOf(e90RackData()));
  car.addAxleSteering("front_steer", "front", SteeringStateSpec{});
  Scene& sc = car.updScene();
  const LaneChangeParams lp{5.0, 0.0, 40.0, 2.0};
  PathControlParams g;
  g.k1_rad_per_s2_per_m = 10;
  g.k2_rad_per_s2 = 2;
  g.k3_rad_per_s2_per_m = 100;
  g.k4_rad_per_s2 = 5;
  g.k5_per_s = 10;
  g.look_ahead_s = 0.6;
  sc.addPlugin(std::make_unique<PathControlPlugin>("path_control", "front_steer", "chassis",
                                                   std::make_shared<LaneChangePath>(lp), g));
  sc.addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 16.0));
  SimTK::State s = car.makeInitialState(16.0);
  SimulationSettings sim;
  sim.t_end_s = 4.0;
  sim.report_interval_s = 0.05;
  sim.integrator.accuracy = 1e-6;
  Recorder rec(sc, {"chassis.x_m", "chassis.y_m", "front_steer.command_rad", "front_steer.rack_travel_m"});
  simulate(sc, s, sim, &rec);
  double peak = 0;
  for (double q : rec.column("front_steer.command_rad")) peak = std::max(peak, std::abs(q));
  std::printf("rack path control: y(4 s) = %.4f m at x = %.2f m, peak command %.4f rad\n",
              rec.column("chassis.y_m").back(), rec.column("chassis.x_m").back(), peak);
  EXPECT_NEAR(rec.column("chassis.y_m").back(), 2.0, 0.05);
}
