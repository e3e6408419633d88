// The suspension springs' options (issue 20): the ride-height option that sets
// the free lengths from the design configuration, and bump and rebound stops.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "test_util.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {

WheeledVehicleParams appendixA() { return WheeledVehicleParams::fromFile("appendix_a.json"); }

struct Rest {
  std::vector<double> spring_length_m, design_length_m, fz_N;
  std::map<std::string, double> outputs;  ///< the asked outputs at rest
  double weight_N = 0, chassis_z_m = 0;
  SimTK::State state;
};

/// The vehicle at rest: the steady-state solver's static equilibrium (makeRestProblem), the front held straight.
Rest restOf(const WheeledVehicleParams& p, const std::vector<std::string>& outputs = {}) {
  WheeledVehicle car(p);
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  if (car.suspension(1).isSteerable())
    car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0));
  std::vector<std::string> wheels;
  for (int c = 0; c < car.numCorners(); ++c) wheels.push_back(car.cornerName(c) + ".wheel");
  const Scene& sc = car.getScene();
  SimTK::State s0 = car.makeInitialState(0.0);
  Rest r;
  sc.getSystem().realize(s0, SimTK::Stage::Position);
  for (int c = 0; c < car.numCorners(); ++c) r.design_length_m.push_back(car.suspension(c / 2).calcSpringLength(s0, c % 2));
  SteadyStateSolver solver(sc, makeRestProblem(sc, "chassis", wheels, 0.0));
  r.state = solver.solve(s0).state;
  sc.getSystem().realize(r.state, SimTK::Stage::Dynamics);
  for (int c = 0; c < car.numCorners(); ++c) {
    r.spring_length_m.push_back(car.suspension(c / 2).calcSpringLength(r.state, c % 2));
    r.fz_N.push_back(sc.evalOutput("tire_" + car.cornerName(c) + ".Fz_N", r.state));
  }
  for (const std::string& o : outputs) r.outputs[o] = sc.hasOutput(o) ? sc.evalOutput(o, r.state) : NAN;
  r.weight_N = car.totalMass() * p.gravity_m_per_s2;
  r.chassis_z_m = car.chassis().getBodyOriginLocation(r.state)[2];
  return r;
}

double& rearStiffness(WheeledVehicleParams& p) {
  return p.updAxle("rear").suspension.block["spring"]["stiffness_N_per_m"].get_ref<double&>();
}

}  // namespace

// With the option every spring sits at its design length at rest (1e-9 m,
// the option's tolerance); without it App. A's data free lengths leave them
// elsewhere, and softening the rear springs lowers the rear. With it, the
// rear spring 20 % softer keeps the design ride height: the springs' lengths do
// not change, only their free lengths do (longer, as a softer spring needs
// more preload for the same load: dl0 = F (1/k' - 1/k)).
TEST(RideHeight, SpringsAtDesignLengthAtRestWhateverTheirStiffness) {
  constexpr double kSofter = 0.8;
  WheeledVehicleParams plain = appendixA();
  const Rest a = restOf(plain);
  WheeledVehicleParams soft = plain;
  rearStiffness(soft) *= kSofter;
  const Rest b = restOf(soft);
  EXPECT_LT(b.spring_length_m[2], a.spring_length_m[2] - 1e-3);  // the rear goes down with the data's free length

  for (double scale : {1.0, kSofter}) {
    WheeledVehicleParams p = plain;
    rearStiffness(p) *= scale;
    p.spring_free_length_from_ride_height = true;
    WheeledVehicleParams::RideHeightReport rep;
    const WheeledVehicleParams q = p.withRideHeightSprings(vehiclePlugins(), &rep);
    EXPECT_FALSE(q.spring_free_length_from_ride_height);
    EXPECT_LE(rep.max_length_error_m, 1e-9);
    EXPECT_LE(rep.iterations, 10);
    const Rest r = restOf(q);
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(r.spring_length_m[c], r.design_length_m[c], 2e-9) << "corner " << c << " scale " << scale;
      EXPECT_NEAR(rep.free_length_m[c], q.axles[c / 2].suspension.block["spring"]["free_length_m"].get<double>(), 0);
    }
    double sum = 0;
    for (double f : r.fz_N) sum += f;
    EXPECT_NEAR(sum, r.weight_N, 1e-9 * r.weight_N);
    // The vehicle built with the option (the constructor applies it) is the same.
    const Rest viaCtor = restOf(p);
    EXPECT_NEAR(viaCtor.chassis_z_m, r.chassis_z_m, 1e-12);
    std::printf("ride height, rear stiffness x%.1f: %d equilibria, free lengths %.6f %.6f m (data %.6f %.6f)\n", scale,
                rep.iterations, rep.free_length_m[0], rep.free_length_m[2],
                plain.axles[0].suspension.block["spring"]["free_length_m"].get<double>(),
                plain.axles[1].suspension.block["spring"]["free_length_m"].get<double>());
  }
  // The softer spring needs the longer free length for the same ride height.
  WheeledVehicleParams p1 = plain, p2 = plain;
  rearStiffness(p2) *= kSofter;
  WheeledVehicleParams::RideHeightReport r1, r2;
  p1.withRideHeightSprings(vehiclePlugins(), &r1);
  p2.withRideHeightSprings(vehiclePlugins(), &r2);
  EXPECT_GT(r2.free_length_m[2], r1.free_length_m[2] + 1e-3);
  EXPECT_NEAR(r2.free_length_m[0], r1.free_length_m[0], 1e-3);  // the front barely changes
}

// The static equilibrium on every formulation (issue 24): App. A with the
// ride-height option and a rear bump stop that carries load at rest, solved on
// the constrained templates (the reference), the reduced ones and the dense
// rows. Each rest meets the force tolerance (1e-6 N) on springs and tires of
// 1e4-1e5 N/m, so positions agree to ~1e-10 m, the stop force to ~1e-5 N.
TEST(RideHeight, RestIsTheSameOnEveryFormulation) {
  WheeledVehicleParams p = appendixA();
  p.spring_free_length_from_ride_height = true;
  const WheeledVehicleParams q = p.withRideHeightSprings(vehiclePlugins());
  WheeledVehicleParams s = q;
  const double lb = restOf(q).spring_length_m[2] + 0.005, kb = 2e5;
  s.updAxle("rear").suspension.block["spring"]["bump_stop"] = {{"length_m", lb}, {"stiffness_N_per_m", kb}};
  std::map<std::string, Rest> rest;
  for (const char* f : {"constrained", "reduced", "dense"}) {
    WheeledVehicleParams v = s;
    v.formulation = f;
    rest[f] = restOf(v, {"rr.bump_stop_N"});
    double sum = 0;
    for (double x : rest[f].fz_N) sum += x;
    EXPECT_NEAR(sum, rest[f].weight_N, 1e-9 * rest[f].weight_N) << f;
    EXPECT_GT(rest[f].outputs.at("rr.bump_stop_N"), 100.0) << f;
  }
  const Rest& ref = rest.at("constrained");
  for (const char* f : {"reduced", "dense"}) {
    const Rest& r = rest.at(f);
    EXPECT_NEAR(r.chassis_z_m, ref.chassis_z_m, 1e-10) << f;
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(r.spring_length_m[c], ref.spring_length_m[c], 1e-10) << f << " corner " << c;
      EXPECT_NEAR(r.fz_N[c], ref.fz_N[c], 1e-5) << f << " corner " << c;
    }
    EXPECT_NEAR(r.outputs.at("rr.bump_stop_N"), ref.outputs.at("rr.bump_stop_N"), 1e-5) << f;
    std::printf("rest on %s: chassis z %.12f m (constrained %.12f), rr bump stop %.6f N (%.6f)\n", f, r.chassis_z_m,
                ref.chassis_z_m, r.outputs.at("rr.bump_stop_N"), ref.outputs.at("rr.bump_stop_N"));
  }
}

// The static equilibrium holds every speed at zero (makeRestProblem): its
// unknowns are the turning problem's less the chassis yaw rate, horizontal
// velocity and the four spins; the equations of those mobilities are checked,
// not solved, so a push along x (10 N on the chassis), which no position
// balances, is an error that names the equation.
TEST(RideHeight, RestProblemHoldsTheSpeedsAndChecksTheCyclicEquations) {
  WheeledVehicle car(appendixA());
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0));
  SimTK::Force::ConstantForce(car.updScene().updForces(), car.chassis(), SimTK::Vec3(0), SimTK::Vec3(10.0, 0, 0));
  std::vector<std::string> wheels;
  for (int c = 0; c < car.numCorners(); ++c) wheels.push_back(car.cornerName(c) + ".wheel");
  const Scene& sc = car.getScene();
  SteadyStateSolver rest(sc, makeRestProblem(sc, "chassis", wheels, 0.0));
  SteadyStateSolver turn(sc, makeSteadyTurningProblem(sc, "chassis", wheels, 0.0));
  EXPECT_EQ(rest.numUnknowns(), turn.numUnknowns() - 7);
  const std::string e = errorOf([&] { rest.solve(car.makeInitialState(0.0)); });
  EXPECT_NE(e.find("generalized force u[3] (mobilizer of body 1, its u 3) = -10"), std::string::npos) << e;
  EXPECT_NE(e.find("checked, not solved"), std::string::npos) << e;
}

TEST(RideHeight, MacPhersonE90AtItsDesignHeight) {
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("bmw_e90.json");
  WheeledVehicleParams::RideHeightReport rep;
  const WheeledVehicleParams q = p.withRideHeightSprings(vehiclePlugins(), &rep);
  const Rest r = restOf(q);
  // Both axles' left corners are the mirror of the right: one free length per
  // axle holds the mean of its two springs at design; the E90's c.m. 1 mm
  // right of the centre plane (bmw_e90.json chassis.com_m) rolls it a little.
  for (int ax = 0; ax < 2; ++ax) {
    const double mean = 0.5 * (r.spring_length_m[2 * ax] + r.spring_length_m[2 * ax + 1]);
    EXPECT_NEAR(mean, r.design_length_m[2 * ax], 2e-9) << "axle " << ax;
    EXPECT_LT(std::abs(r.spring_length_m[2 * ax] - r.spring_length_m[2 * ax + 1]), 1e-3) << "axle " << ax;
  }
  std::printf("e90 ride height: %d equilibria, free lengths front %.6f rear %.6f m (data %.6f %.6f), chassis c.m. z "
              "%.4f m, springs right-left %.2e %.2e m\n",
              rep.iterations, rep.free_length_m[0], rep.free_length_m[2],
              p.axles[0].suspension.block["spring"]["free_length_m"].get<double>(),
              p.axles[1].suspension.block["spring"]["free_length_m"].get<double>(), r.chassis_z_m,
              r.spring_length_m[0] - r.spring_length_m[1], r.spring_length_m[2] - r.spring_length_m[3]);
}

TEST(RideHeight, BadDataIsNamed) {
  WheeledVehicleParams p = appendixA();
  p.updAxle("rear").suspension.block["spring"].erase("free_length_m");
  const std::string e = errorOf([&] { p.withRideHeightSprings(vehiclePlugins()); });
  EXPECT_NE(e.find("spring.free_length_m"), std::string::npos) << e;
  EXPECT_NE(e.find("spring_free_length_from_ride_height"), std::string::npos) << e;
}

// The stop force F(l) against its closed form; bad stop data named.
TEST(SpringStops, ClosedForm) {
  SpringStopParams s;
  s.bump = s.rebound = true;
  s.bump_length_m = 0.2, s.bump_stiffness_N_per_m = 5e5;
  s.rebound_length_m = 0.3, s.rebound_stiffness_N_per_m = 2e5;
  EXPECT_NEAR(s.calcForce(0.19), 5e5 * 0.01, 1e-9);
  EXPECT_DOUBLE_EQ(s.calcForce(0.25), 0.0);
  EXPECT_DOUBLE_EQ(s.calcForce(0.2), 0.0);
  EXPECT_NEAR(s.calcForce(0.32), -2e5 * 0.02, 1e-9);
  EXPECT_NE(errorOf([&] {
              SpringStopParams t = s;
              t.rebound_length_m = 0.15;
              t.validate("axles.rear.suspension.spring");
            }).find("axles.rear.suspension.spring.bump_stop.length_m (0.2) must be below rebound_stop.length_m"),
            std::string::npos);
}

// A bump stop on App. A's rear springs that engages 5 mm above their rest
// length: at rest it carries load (its output is k_b (L_b - l) of the spring
// length output), the rear stands higher, the tires still carry the weight.
TEST(SpringStops, BumpStopCarriesLoadAtRest) {
  WheeledVehicleParams plain = appendixA();
  const Rest a = restOf(plain);
  WheeledVehicleParams p = plain;
  const double lb = a.spring_length_m[2] + 0.005, kb = 2e5;
  p.updAxle("rear").suspension.block["spring"]["bump_stop"] = {{"length_m", lb}, {"stiffness_N_per_m", kb}};
  const Rest b = restOf(p, {"rr.spring_length_m", "rr.bump_stop_N", "rf.bump_stop_N", "rr.rebound_stop_N"});
  const double l = b.outputs.at("rr.spring_length_m");
  EXPECT_NEAR(l, b.spring_length_m[2], 1e-12);
  const double f = b.outputs.at("rr.bump_stop_N");
  EXPECT_GT(f, 100.0);
  EXPECT_NEAR(f, kb * (lb - l), 1e-9 * f);
  EXPECT_GT(b.spring_length_m[2], a.spring_length_m[2] + 1e-4);  // the stop lifts the rear
  EXPECT_NEAR(b.spring_length_m[0], a.spring_length_m[0], 2e-3);
  double sum = 0;
  for (double x : b.fz_N) sum += x;
  EXPECT_NEAR(sum, b.weight_N, 1e-9 * b.weight_N);
  EXPECT_TRUE(std::isnan(b.outputs.at("rf.bump_stop_N")));  // the front has none
  EXPECT_TRUE(std::isnan(b.outputs.at("rr.rebound_stop_N")));
}

TEST(SpringStops, BadDataIsNamed) {
  WheeledVehicleParams p = appendixA();
  p.updAxle("rear").suspension.block["spring"]["bump_stop"] = {{"length_m", 0.2}, {"stiffness_N_per_m", -1.0}};
  const std::string e = errorOf([&] { WheeledVehicle car(p); });
  EXPECT_NE(e.find("bump_stop.stiffness_N_per_m"), std::string::npos) << e;
  WheeledVehicleParams q = appendixA();
  q.updAxle("rear").suspension.block["spring"]["rebound_stop"] = {{"length_m", 0.3}, {"stiffnes_N_per_m", 1e5}};
  const std::string e2 = errorOf([&] { WheeledVehicle car(q); });
  EXPECT_NE(e2.find("rebound_stop.stiffness_N_per_m: missing"), std::string::npos) << e2;
}

// The option on a dependent axle (App. A with the solid rear axle of
// appendix_a_solid_rear.json): both rear springs at their design length at
// rest, the tires carrying the weight; a bump stop on its spring line reports
// k (L - l) of that line.
TEST(RideHeight, SolidAxleRear) {
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a_solid_rear.json");
  WheeledVehicleParams::RideHeightReport rep;
  const WheeledVehicleParams q = p.withRideHeightSprings(vehiclePlugins(), &rep);
  const Rest r = restOf(q);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(r.spring_length_m[c], r.design_length_m[c], 2e-9) << "corner " << c;
  double sum = 0;
  for (double f : r.fz_N) sum += f;
  EXPECT_NEAR(sum, r.weight_N, 1e-9 * r.weight_N);
  std::printf("solid rear ride height: %d equilibria, rear free length %.6f m (data %.6f)\n", rep.iterations,
              rep.free_length_m[2], p.axles[1].suspension.block["spring"]["free_length_m"].get<double>());
  WheeledVehicleParams s = q;
  const double lb = r.spring_length_m[2] + 0.003, kb = 1e5;
  s.updAxle("rear").suspension.block["spring"]["bump_stop"] = {{"length_m", lb}, {"stiffness_N_per_m", kb}};
  const Rest b = restOf(s, {"rr.spring_length_m", "rr.bump_stop_N", "lr.bump_stop_N"});
  EXPECT_NEAR(b.outputs.at("rr.bump_stop_N"), kb * (lb - b.outputs.at("rr.spring_length_m")), 1e-6);
  EXPECT_GT(b.outputs.at("rr.bump_stop_N"), 10.0);
  EXPECT_GT(b.outputs.at("lr.bump_stop_N"), 10.0);
}
