// The solid_axle suspension template (vehicles/templates/solid_axle):
//  1. kinematics against the independent reference (tests/reference: the
//     axle's pose closed by Newton on the four link lengths and the two
//     wheel-centre heights, written apart from any multibody model): camber,
//     toe, track change and recession of both wheels and the axle's roll over
//     right and left wheel travels in +-80 mm (a 9 x 9 grid: parallel bump,
//     opposite roll and every mix), on two geometries: the triangulated
//     four-link of vehicles/data/appendix_a_solid_rear.json and a
//     trailing-link + torque-link + Panhard-rod axle (both plausible
//     geometries of this project's, not published cars');
//  2. degrees of freedom, corner mass, the shared housing's names, mirror
//     symmetry of the four-link and the Panhard rod's sideways shift, bad data
//     named;
//  3. App. A with the solid rear axle: built, static tire loads = weight,
//     front axle load = moment balance, a straight coast.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "reference/suspension_kinematics.h"
#include "test_util.h"
#include "vdyn/core/recorder.h"
#include "vdyn/core/simulation.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/templates/solid_axle.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;
namespace kr = vdyn::kinematics_reference;
using SimTK::Vec3;

namespace {

kr::Vec3 arr(const Vec3& v) { return {v[0], v[1], v[2]}; }

/// The rear suspension block of the App. A solid-rear data file.
Json solidRearBlock() {
  return ParamReader::fromFile("appendix_a_solid_rear.json").json().at("axles").at("rear").at("suspension");
}

/// Its triangulated four-link, with a static camber and toe-in of its own
/// (the data file has none) so the signs are exercised.
SolidAxleParams fourLink() {
  SolidAxleParams p = SolidAxleParams::fields().read(ParamReader::fromJson(solidRearBlock(), "four_link"));
  p.camber_rad = -0.010;
  p.toe_in_rad = 0.003;
  p.validate("four_link");
  return p;
}

/// Two lower trailing links, a central upper (torque) link and a Panhard rod
/// from the chassis on the left to the axle on the right, its axle end 70 mm
/// below its chassis end: not symmetric. Positive camber and toe-out.
SolidAxleParams panhard() {
  SolidAxleParams p = fourLink();
  p.links = {{"lower_right", Vec3(-0.50, -0.45, -0.33), Vec3(-0.97, -0.45, -0.40)},
             {"lower_left", Vec3(-0.50, 0.45, -0.33), Vec3(-0.97, 0.45, -0.40)},
             {"torque_link", Vec3(-0.64, 0.05, -0.12), Vec3(-0.92, 0.05, -0.15)},
             {"panhard_rod", Vec3(-1.05, 0.45, -0.20), Vec3(-1.05, -0.45, -0.27)}};
  p.camber_rad = 0.005;
  p.toe_in_rad = -0.002;
  p.validate("panhard");
  return p;
}

kr::SolidAxleHardpoints referenceHardpoints(const SolidAxleParams& p) {
  kr::SolidAxleHardpoints hp;
  hp.spindle_right = arr(p.spindle_m[0]);
  hp.spindle_left = arr(p.spindle_m[1]);
  for (const SolidAxleLink& l : p.links) hp.links.push_back({l.name, arr(l.chassis_m), arr(l.axle_m)});
  hp.camber_rad = p.camber_rad;
  hp.toe_in_rad = p.toe_in_rad;
  return hp;
}

/// One solid axle on a chassis welded to ground (chassis frame = ground).
/// With `heights`, each wheel centre is held in a horizontal plane carried by
/// a body on a translation mobilizer from ground (a point-in-plane
/// constraint): locking those mobilizers at a height sets the wheel travels,
/// and the assembler closes the four links with them.
struct AxleRig {
  Scene scene;
  SimTK::MobilizedBody::Weld chassis;
  SolidAxleSuspension susp;
  SimTK::MobilizedBody::Translation height[2];
  AxleRig(const SolidAxleParams& p, bool heights) : susp(p) {
    const SimTK::Body::Rigid body(SimTK::MassProperties(1000, Vec3(0), SimTK::Inertia(1)));
    chassis = SimTK::MobilizedBody::Weld(scene.updMatter().Ground(), SimTK::Transform(), body, SimTK::Transform());
    scene.addBody("chassis", chassis);
    const std::string prefixes[2] = {"rr.", "lr."};
    susp.build(scene, chassis, prefixes, nullptr);
    if (!heights) return;
    for (int side = 0; side < 2; ++side) {
      height[side] = SimTK::MobilizedBody::Translation(scene.updMatter().Ground(), SimTK::Transform(), body,
                                                       SimTK::Transform());
      SimTK::MobilizedBody knuckle = susp.getCorner(side).knuckle;  // a handle: the constraint takes it non-const
      SimTK::Constraint::PointInPlane(height[side], SimTK::UnitVec3(SimTK::ZAxis), 0.0, knuckle, Vec3(0));
    }
  }
  /// Wheel travels (m, + up) from the configuration in s.
  void setTravels(SimTK::State& s, double zr, double zl) const {
    const double z[2] = {zr, zl};
    SimTK::Assembler assembler(scene.getSystem());
    for (int side = 0; side < 2; ++side) {
      height[side].setQ(s, Vec3(0, 0, susp.getParams().spindle_m[side][2] + z[side]));
      assembler.lockMobilizer(height[side].getMobilizedBodyIndex());
      assembler.lockMobilizer(susp.getCorner(side).wheel.getMobilizedBodyIndex());
    }
    assembler.setAccuracy(1e-13);
    assembler.assemble(s);
    scene.getSystem().realize(s, SimTK::Stage::Position);
  }
};

struct Worst {
  double centre = 0, spin = 0, camber = 0, toe = 0, track = 0, recession = 0, roll = 0, travel = 0, gap = 0;
};

/// The template against the reference over a 9 x 9 grid of travels in
/// [-0.08, 0.08] m, visited in snake order from design (each assembly starts
/// from a neighbour 20 mm away).
Worst compareWithReference(const SolidAxleParams& p, const char* name) {
  AxleRig rig(p, true);
  SimTK::State s = rig.scene.getDefaultState();
  rig.scene.getSystem().realize(s, SimTK::Stage::Position);
  EXPECT_LT(rig.susp.calcLoopGap(s, 0), 1e-15);  // the design lengths are the data's
  // The wheels turned on their spin pins: the spin axis read from the wheel
  // body is the pin's own axis only if the pin turns about it.
  rig.susp.getCorner(0).wheel.setOneQ(s, 0, 1.0);
  rig.susp.getCorner(1).wheel.setOneQ(s, 0, -2.0);
  const kr::SolidAxleHardpoints hp = referenceHardpoints(p);
  for (double z = -0.02; z >= -0.081; z -= 0.02) rig.setTravels(s, z, z);  // to the grid's first corner
  Worst w;
  const int n = 9;
  for (int i = 0; i < n; ++i)
    for (int jj = 0; jj < n; ++jj) {
      const int j = i % 2 == 0 ? jj : n - 1 - jj;
      const double zr = -0.08 + 0.02 * i, zl = -0.08 + 0.02 * j;
      rig.setTravels(s, zr, zl);
      w.gap = std::max(w.gap, rig.susp.calcLoopGap(s, 0));
      const kr::AxleKinematics ref = kr::solidAxleKinematics(hp, zr, zl);
      EXPECT_LT(ref.right.loop_residual, 1e-12);
      Vec3 centre[2];
      for (int side = 0; side < 2; ++side) {
        const SolidAxleCorner& c = rig.susp.getCorner(side);
        const kr::WheelKinematics& k = side == 0 ? ref.right : ref.left;
        const double yOut = side == 0 ? -1 : 1;
        w.travel = std::max(w.travel, std::abs(rig.susp.getSuspensionCoordinate(s, side) - (side == 0 ? zr : zl)));
        centre[side] = c.wheel.getBodyOriginLocation(s);
        const Vec3 spinLeft = c.wheel.getBodyRotation(s) * rig.susp.getSpinAxis(side).asVec3();
        const Vec3 out = yOut * spinLeft;
        for (int m = 0; m < 3; ++m) {
          w.centre = std::max(w.centre, std::abs(centre[side][m] - k.wheel_centre_m[m]));
          w.spin = std::max(w.spin, std::abs(out[m] - k.spin_axis_out[m]));
        }
        // The reference's definitions (its header): camber + top outward, toe-in +,
        // track change + outward, recession dx + forward.
        const double camber = std::asin(-out[2]), toe = std::atan2(out[0], out[1] * yOut);
        const double track = (centre[side][1] - p.spindle_m[side][1]) * yOut;
        const double dx = centre[side][0] - p.spindle_m[side][0];
        EXPECT_NEAR(camber, k.camber_rad, 1e-6) << name << " side " << side << " " << zr << " " << zl;
        EXPECT_NEAR(toe, k.toe_in_rad, 1e-6) << name << " side " << side << " " << zr << " " << zl;
        EXPECT_NEAR(track, k.track_change_m, 1e-6) << name << " side " << side << " " << zr << " " << zl;
        EXPECT_NEAR(dx, k.dx_m, 1e-6) << name << " side " << side << " " << zr << " " << zl;
        w.camber = std::max(w.camber, std::abs(camber - k.camber_rad));
        w.toe = std::max(w.toe, std::abs(toe - k.toe_in_rad));
        w.track = std::max(w.track, std::abs(track - k.track_change_m));
        w.recession = std::max(w.recession, std::abs(dx - k.dx_m));
      }
      const Vec3 d = centre[1] - centre[0];
      const double roll = std::asin(d[2] / d.norm());
      EXPECT_NEAR(roll, ref.roll_rad, 1e-6) << name << " " << zr << " " << zl;
      w.roll = std::max(w.roll, std::abs(roll - ref.roll_rad));
    }
  std::printf("solid_axle %s vs reference, 81 travels in [-0.08, 0.08]^2 m: wheel centre %.2e m, spin axis %.2e, "
              "camber %.2e rad, toe %.2e rad, track change %.2e m, recession %.2e m, roll %.2e rad (travel reached "
              "to %.2e m, links closed to %.2e m)\n",
              name, w.centre, w.spin, w.camber, w.toe, w.track, w.recession, w.roll, w.travel, w.gap);
  return w;
}

}  // namespace

// --- 1. kinematics against the independent reference --------------------------

TEST(SolidAxle, FourLinkKinematicsMatchTheIndependentReference) {
  const Worst w = compareWithReference(fourLink(), "four_link");
  EXPECT_LT(w.centre, 1e-6);
  EXPECT_LT(w.spin, 1e-6);
  EXPECT_LT(w.travel, 1e-10);
  EXPECT_LT(w.gap, 1e-11);
}

TEST(SolidAxle, PanhardKinematicsMatchTheIndependentReference) {
  const Worst w = compareWithReference(panhard(), "panhard");
  EXPECT_LT(w.centre, 1e-6);
  EXPECT_LT(w.spin, 1e-6);
  EXPECT_LT(w.travel, 1e-10);
  EXPECT_LT(w.gap, 1e-11);
}

// --- 2. structure, symmetry, data errors ---------------------------------------

TEST(SolidAxle, DegreesOfFreedomMassAndTheSharedHousing) {
  const SolidAxleParams p = fourLink();
  AxleRig rig(p, false);
  SimTK::State s = rig.scene.getDefaultState();
  rig.scene.getSystem().realize(s, SimTK::Stage::Instance);
  // Housing 6 + two wheel spins - four links = 2 wheel travels + 2 spins.
  EXPECT_EQ(s.getNU(), 8);
  EXPECT_EQ(s.getNUDotErr(), 4);
  EXPECT_EQ(s.getNU() - s.getNUDotErr(), 4);
  // Half the 60 kg housing, a 5 kg knuckle, a 30 kg wheel (the data file).
  EXPECT_DOUBLE_EQ(rig.susp.calcCornerMass(0), 65.0);
  EXPECT_DOUBLE_EQ(rig.susp.calcCornerMass(0) + rig.susp.calcCornerMass(1), 60.0 + 2 * (5.0 + 30.0));
  // One housing under both corners' names; a knuckle and a wheel per side.
  const auto idx = [](const SimTK::MobilizedBody& b) { return int(b.getMobilizedBodyIndex()); };
  EXPECT_EQ(idx(rig.susp.getBody(0, "axle")), idx(rig.susp.getHousing()));
  EXPECT_EQ(idx(rig.susp.getBody(1, "axle")), idx(rig.susp.getHousing()));
  EXPECT_EQ(idx(rig.scene.getBody("lr.axle")), idx(rig.scene.getBody("rr.axle")));
  EXPECT_NE(idx(rig.susp.getBody(0, "knuckle")), idx(rig.susp.getBody(1, "knuckle")));
  EXPECT_EQ(idx(rig.susp.getBody(1, "wheel")), idx(rig.susp.getCorner(1).wheel));
  EXPECT_FALSE(rig.susp.isSteerable());
  KinematicCorner k;
  EXPECT_FALSE(rig.susp.getKinematicCorner(0, &k));
  EXPECT_NE(test::errorOf([&] { rig.susp.getBody(0, "lower_arm"); }).find("roles: axle, knuckle, wheel"),
            std::string::npos);
  // The left spin axis is the right one mirrored as an axial vector; -10 mrad
  // of camber tilts the right wheel's axis (pointing left) up.
  const Vec3 r = p.calcSpinAxis(true).asVec3(), l = p.calcSpinAxis(false).asVec3();
  EXPECT_NEAR((l - Vec3(-r[0], r[1], -r[2])).norm(), 0, 1e-15);
  EXPECT_NEAR(std::asin(r[2]), p.camber_rad, 1e-15);
  // At design the wheel travels are 0 and the links closed.
  rig.scene.getSystem().realize(s, SimTK::Stage::Position);
  EXPECT_EQ(rig.susp.getSuspensionCoordinate(s, 0), 0.0);
  EXPECT_EQ(rig.susp.getSuspensionCoordinate(s, 1), 0.0);
  EXPECT_LT(rig.susp.calcLoopGap(s, 0), 1e-15);
}

TEST(SolidAxle, ShiftingTheChassisFrameMovesEveryPoint) {
  // Data in a frame whose origin is d behind the c.m. frame: shifted by -d,
  // every chassis-frame point is the original one (the vehicle's chassis com_m).
  const SolidAxleParams p = fourLink();
  const Vec3 d(0.3, -0.02, 0.1);
  SolidAxleParams q = p;
  q.axle_com_m += d;
  for (int side = 0; side < 2; ++side) q.spindle_m[side] += d, q.spring_chassis_m[side] += d, q.spring_axle_m[side] += d;
  for (SolidAxleLink& l : q.links) l.chassis_m += d, l.axle_m += d;
  SolidAxleSuspension susp(q);
  susp.shiftChassisFrame(-d);
  const SolidAxleParams& r = susp.getParams();
  double worst = (r.axle_com_m - p.axle_com_m).norm();
  for (int side = 0; side < 2; ++side) {
    worst = std::max(worst, (susp.calcWheelCentreInChassis(side) - p.spindle_m[side]).norm());
    worst = std::max(worst, (r.spring_chassis_m[side] - p.spring_chassis_m[side]).norm());
    worst = std::max(worst, (r.spring_axle_m[side] - p.spring_axle_m[side]).norm());
  }
  for (std::size_t i = 0; i < p.links.size(); ++i) {
    worst = std::max(worst, (r.links[i].chassis_m - p.links[i].chassis_m).norm());
    worst = std::max(worst, (r.links[i].axle_m - p.links[i].axle_m).norm());
  }
  EXPECT_LT(worst, 1e-15);
}

TEST(SolidAxle, FourLinkMirrorsAndThePanhardRodShiftsTheAxle) {
  // The four-link is symmetric: travels (a, b) give the right wheel what
  // (b, a) gives the left, and the opposite roll.
  {
    const SolidAxleParams p = fourLink();
    AxleRig rig(p, true);
    SimTK::State s = rig.scene.getDefaultState();
    for (auto [a, b] : {std::pair{0.06, -0.03}, std::pair{-0.05, 0.02}, std::pair{0.04, 0.04}}) {
      rig.setTravels(s, a, b);
      const Vec3 r = rig.susp.getCorner(0).wheel.getBodyOriginLocation(s);
      const Vec3 rs = rig.susp.getCorner(0).knuckle.getBodyRotation(s) * rig.susp.getSpinAxis(0).asVec3();
      rig.setTravels(s, b, a);
      const Vec3 l = rig.susp.getCorner(1).wheel.getBodyOriginLocation(s);
      const Vec3 ls = rig.susp.getCorner(1).knuckle.getBodyRotation(s) * rig.susp.getSpinAxis(1).asVec3();
      EXPECT_NEAR((l - Vec3(r[0], -r[1], r[2])).norm(), 0, 1e-10) << a << " " << b;
      EXPECT_NEAR((ls - Vec3(-rs[0], rs[1], -rs[2])).norm(), 0, 1e-10) << a << " " << b;
    }
  }
  // The Panhard rod runs from the chassis on the left down to the axle on the
  // right: in parallel bump both wheels move sideways together (roll 0, no
  // yaw: the trailing links are symmetric), to the right at +80 mm (the rod
  // swings toward the horizontal: to first order dy/dz = -0.07/0.90 at the
  // rod's end) and to the left at -80 mm.
  const SolidAxleParams p = panhard();
  AxleRig rig(p, true);
  SimTK::State s = rig.scene.getDefaultState();
  double shift[2] = {0, 0};
  int k = 0;
  for (double z : {0.08, -0.08}) {
    for (double t = 0.02 * (z > 0 ? 1 : -1); std::abs(t) <= 0.0801; t += 0.02 * (z > 0 ? 1 : -1)) rig.setTravels(s, t, t);
    const Vec3 r = rig.susp.getCorner(0).wheel.getBodyOriginLocation(s) - p.spindle_m[0];
    const Vec3 l = rig.susp.getCorner(1).wheel.getBodyOriginLocation(s) - p.spindle_m[1];
    EXPECT_NEAR(r[1], l[1], 1e-12) << z;  // one sideways shift of the whole axle
    EXPECT_NEAR(r[0], l[0], 1e-12) << z;  // no yaw
    shift[k++] = r[1];
    s = rig.scene.getDefaultState();  // back to design
  }
  std::printf("panhard axle: sideways shift %.4f mm at +80 mm, %.4f mm at -80 mm\n", 1e3 * shift[0], 1e3 * shift[1]);
  EXPECT_LT(shift[0], -1e-3);
  EXPECT_GT(shift[1], 1e-3);
}

TEST(SolidAxle, BadDataIsNamed) {
  const std::string where = "car.json: axles.rear.suspension";
  auto error = [&](const Json& block) {
    // Read as the vehicle reads it: the block at its place in a data file.
    const ParamReader file = ParamReader::fromJson({{"axles", {{"rear", {{"suspension", block}}}}}}, "car.json");
    return test::errorOf(
        [&] { makeSuspension(vehiclePlugins(), file.child("axles").child("rear").child("suspension")); });
  };
  ASSERT_EQ(error(solidRearBlock()), "(no error)");
  Json b = solidRearBlock();
  b["links"].erase(3);
  EXPECT_EQ(error(b), where + ".links: a solid axle needs exactly 4 links (6 - 4 = 2 degrees of freedom, the two "
                              "wheel travels), got 3");
  b = solidRearBlock();
  b["links"][2]["axle_m"] = b["links"][2]["chassis_m"];
  EXPECT_EQ(error(b), where + ".links[2] (\"upper_right\"): chassis_m [-0.68, -0.38, -0.14] and axle_m [-0.68, "
                              "-0.38, -0.14] coincide: a link of zero length (less than 1 um)");
  b = solidRearBlock();
  b["hardpoints_m"]["spindle_right"] = {-0.97, 0.60, -0.30};
  EXPECT_EQ(error(b), where + ".hardpoints_m.spindle_right must lie on the right (y < 0), got [-0.97, 0.6, -0.3]");
  b = solidRearBlock();
  b["hardpoints_m"]["spindle_left"] = {-0.97, -0.60, -0.30};
  EXPECT_EQ(error(b), where + ".hardpoints_m.spindle_left must lie on the left (y > 0), got [-0.97, -0.6, -0.3]");
  // Four parallel trailing links: nothing holds the axle sideways.
  b = solidRearBlock();
  b["links"][2]["chassis_m"] = {-0.50, -0.20, -0.14};
  b["links"][2]["axle_m"] = {-0.97, -0.20, -0.14};
  b["links"][3]["chassis_m"] = {-0.50, 0.20, -0.14};
  b["links"][3]["axle_m"] = {-0.97, 0.20, -0.14};
  b["links"][0]["chassis_m"] = {-0.50, -0.45, -0.40};
  b["links"][1]["chassis_m"] = {-0.50, 0.45, -0.40};
  const std::string e = error(b);
  EXPECT_NE(e.find(where + ".links: the links (lower_right, lower_left, upper_right, upper_left) and the two wheel "
                           "heights do not fix the axle's pose at design (singular linkage, conditioning "),
            std::string::npos)
      << e;
  b = solidRearBlock();
  b["links"][1]["name"] = "lower_right";
  EXPECT_EQ(error(b), where + ".links[1].name: \"lower_right\" names another link too");
  b = solidRearBlock();
  b["spring"]["stiffness_N_per_m"] = 0.0;
  EXPECT_NE(error(b).find(where + ".spring.stiffness_N_per_m"), std::string::npos) << error(b);
  // A rear solid axle offers no knuckles to steer.
  WheeledVehicle car(WheeledVehicleParams::fromFile("appendix_a_solid_rear.json"));
  EXPECT_NE(test::errorOf([&] { car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0)); })
                .find("steering plugin 'rear_steer' steers axle 'rear'"),
            std::string::npos);
}

// --- 3. App. A with the solid rear axle ---------------------------------------

TEST(SolidAxle, AppendixASolidRearCarriesItsWeightAndCoastsStraight) {
  const WheeledVehicleParams data = WheeledVehicleParams::fromFile("appendix_a_solid_rear.json");
  WheeledVehicle car(data);
  ASSERT_EQ(car.suspension(1).templateName(), "solid_axle");
  // 800 + 2 (0.5 + 5 + 0.5 + 20) front + 60 housing + 2 (5 + 30) rear.
  EXPECT_DOUBLE_EQ(car.totalMass(), 982.0);
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  const Scene& sc = car.getScene();
  const SimTK::State s0 = car.makeInitialState(0.0);
  // Chassis 6 + front 2 x (arm 1 + knuckle 3 + upper arm 1 + spin 1 - ball 3 - steer 1)
  // + rear (housing 6 + 2 spins - 4 links).
  EXPECT_EQ(car.degreesOfFreedom(s0), 14);
  // Static equilibrium (makeRestProblem: speeds held at zero, chassis x, y,
  // yaw and the spin angles ineffective), as the vehicle report solves it.
  std::vector<std::string> wheels;
  for (int c = 0; c < car.numCorners(); ++c) wheels.push_back(car.cornerName(c) + ".wheel");
  SteadyStateSolver solver(sc, makeRestProblem(sc, "chassis", wheels, 0));
  SimTK::State s = solver.solve(s0).state;
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  const double weight = car.totalMass() * data.gravity_m_per_s2;
  double load = 0, axle[2] = {0, 0}, xc[2] = {0, 0}, fz[4];
  for (int c = 0; c < 4; ++c) {
    const TireContact k = car.tire(c).calcContact(s);
    fz[c] = k.forces.fz_N;
    load += fz[c];
    axle[c / 2] += fz[c];
    xc[c / 2] += fz[c] * k.p_GC[0];
  }
  const double xf = xc[0] / axle[0], xr = xc[1] / axle[1];
  const double comX = sc.getMatter().calcSystemMassCenterLocationInGround(s)[0];
  const double frontFromMoments = load * (comX - xr) / (xf - xr);
  const double travel[2] = {car.suspension(1).getSuspensionCoordinate(s, 0), car.suspension(1).getSuspensionCoordinate(s, 1)};
  std::printf("appendix_a_solid_rear at rest: loads %.3f %.3f %.3f %.3f N (sum %.6f N, weight %.6f N), front %.6f N "
              "against %.6f N from the moments; rear wheel travel %.2f / %.2f mm from design\n",
              fz[0], fz[1], fz[2], fz[3], load, weight, axle[0], frontFromMoments, 1e3 * travel[0], 1e3 * travel[1]);
  EXPECT_NEAR(load, weight, 1e-9 * weight);
  EXPECT_NEAR(axle[0], frontFromMoments, 1e-6 * axle[0]);
  EXPECT_NEAR(fz[2], fz[3], 1e-6 * fz[2]);  // the four-link is symmetric
  EXPECT_NEAR(fz[0], fz[1], 1e-6 * fz[0]);
  // The springs carry the rear at about the design height (free length set
  // for the chassis' rear share; the tires' deflection is the vehicle's).
  for (double t : travel) EXPECT_LT(std::abs(t), 0.01);
  EXPECT_NEAR(travel[0], travel[1], 1e-9);

  // A 2 s coast from 10 m/s, the front wheels held straight: it stays on its
  // line (the car is symmetric) and keeps its speed (no rolling resistance).
  WheeledVehicle coast(data);
  coast.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  SimTK::State st = coast.makeInitialState(10.0);
  SimulationSettings sim;
  sim.t_end_s = 2.0;
  sim.report_interval_s = 0.1;
  sim.integrator.accuracy = 1e-7;
  Recorder rec(coast.getScene(), {"chassis.forward_speed_m_s", "chassis.y_m", "chassis.yaw_rad", "chassis.roll_rad",
                                  "tire_rf.Fz_N", "tire_lf.Fz_N", "tire_rr.Fz_N", "tire_lr.Fz_N"});
  const RunSummary run = simulate(coast.getScene(), st, sim, &rec);
  EXPECT_NEAR(run.sim_time_s, 2.0, 1e-12);
  const double u = rec.column("chassis.forward_speed_m_s").back();
  double final = 0;
  for (const char* c : {"tire_rf.Fz_N", "tire_lf.Fz_N", "tire_rr.Fz_N", "tire_lr.Fz_N"}) final += rec.column(c).back();
  std::printf("coast: speed %.6f m/s, y %.3e m, yaw %.3e rad, roll %.3e rad, tire loads %.3f N (weight %.3f N) at 2 s\n",
              u, rec.column("chassis.y_m").back(), rec.column("chassis.yaw_rad").back(),
              rec.column("chassis.roll_rad").back(), final, weight);
  EXPECT_NEAR(u, 10.0, 0.05);
  for (std::size_t i = 0; i < rec.size(); ++i) {
    EXPECT_LT(std::abs(rec.column("chassis.y_m")[i]), 1e-6) << rec.time()[i];
    EXPECT_LT(std::abs(rec.column("chassis.yaw_rad")[i]), 1e-6) << rec.time()[i];
    EXPECT_LT(std::abs(rec.column("chassis.roll_rad")[i]), 1e-6) << rec.time()[i];
  }
  EXPECT_LT(run.max_constraint_error, 1e-6);
}
