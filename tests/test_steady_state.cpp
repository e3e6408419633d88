// Steady-state solver (plugins/steady_state): closed forms of the linear
// bicycle (yaw rate, side slip, critical speed, d r / d delta), agreement with
// a long transient, restart, continuation, and the failure report.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/core/simulation.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering/steering.h"
#include "vdyn/steering_ratio/linear_ratio.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {
const double kDeg = SimTK::Pi / 180;

struct BikeCase {
  std::unique_ptr<Bicycle> bike;
  std::shared_ptr<HoldCommand> steer;
  const SpeedHoldPlugin* speed = nullptr;
  std::unique_ptr<SteadyStateSolver> solver;
  SimTK::State start;
};

BikeCase makeBike(const std::string& tire, double U, double delta) {
  BicycleParams p = BicycleParams::fromFile("bicycle.json");
  if (tire == "linear") p.tire = p.tire.linearised();
  else p.tire.plugin = tire;
  BikeCase c;
  c.bike = std::make_unique<Bicycle>(p);
  c.steer = std::make_shared<HoldCommand>(0.0);
  c.bike->addFrontSteering("front_steer", c.steer);
  c.speed = &static_cast<const SpeedHoldPlugin&>(
      c.bike->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", U)));
  c.start = c.bike->makeInitialState(U);  // straight, unsteered
  c.steer->setAngle(delta);
  c.solver = std::make_unique<SteadyStateSolver>(
      c.bike->getScene(), makeSteadyTurningProblem(c.bike->getScene(), "chassis", {"front_axle", "rear_axle"}, 0.0));
  return c;
}

/// The bicycle as the linear bicycle (6.1)-(6.9) of vdyn/steering_ratio/linear_ratio.h,
/// two tires per axle.
LinearBicycleParams linearOf(const Bicycle& bike) {
  LinearBicycleParams p;
  p.mass_kg = bike.totalMass();
  p.front_axle_to_com_m = bike.distanceToFrontAxle();
  p.rear_axle_to_com_m = bike.distanceToRearAxle();
  p.front_cornering_stiffness_N_per_rad = p.rear_cornering_stiffness_N_per_rad =
      2 * bike.params().tire.getNumber("cornering_stiffness_N_per_rad");
  return p;
}

/// Side slip of the whole vehicle's centre of mass (the linear bicycle's point).
double comSideSlip(const Bicycle& bike, const SimTK::State& s) {
  const SimTK::SimbodyMatterSubsystem& m = bike.getScene().getMatter();
  const SimTK::Vec3 v = m.calcSystemMassCenterVelocityInGround(s);
  const SimTK::Rotation& R = bike.chassis().getBodyRotation(s);
  return std::atan2(SimTK::dot(v, R.y()), SimTK::dot(v, R.x()));
}
}  // namespace

TEST(SteadyState, LinearTireBicycleMatchesTheClosedForm) {
  const double U = 10.0, d = 0.5 * kDeg;
  BikeCase c = makeBike("linear", U, d);
  const SteadyStateResult r = c.solver->solve(c.start);
  const LinearBicycleParams lin = linearOf(*c.bike);
  const double yaw = c.bike->getScene().evalOutput("chassis.yaw_rate_rad_s", r.state);
  const double beta = comSideSlip(*c.bike, r.state);
  std::printf("yaw rate %.8f (closed form %.8f), side slip %.8f (%.8f), %d iterations\n", yaw, calcLinearSteadyYawRate(lin, U, d, 0), beta,
              calcLinearSteadySideSlip(lin, U, d, 0), r.iterations);
  EXPECT_NEAR(yaw, calcLinearSteadyYawRate(lin, U, d, 0), 0.01 * calcLinearSteadyYawRate(lin, U, d, 0));
  EXPECT_NEAR(beta, calcLinearSteadySideSlip(lin, U, d, 0), 0.01 * std::abs(calcLinearSteadySideSlip(lin, U, d, 0)));
  // The residual at the solution is below the tolerances.
  EXPECT_LE(r.force_residual, c.solver->options().force_tolerance);
  EXPECT_LE(r.position_error, c.solver->options().position_tolerance);
  EXPECT_LE(r.velocity_error, c.solver->options().velocity_tolerance);
  EXPECT_LE(r.rate_residual, c.solver->options().rate_tolerance);
  // And it is the speed asked for.
  EXPECT_NEAR(c.bike->getScene().evalOutput("chassis.forward_speed_m_s", r.state), U * std::cos(
      c.bike->getScene().evalOutput("chassis.side_slip_rad", r.state)), 1e-9);
}

TEST(SteadyState, RestartFromTheSolutionNeedsAtMostOneIteration) {
  BikeCase c = makeBike("gim", 10.0, 2.0 * kDeg);
  const SteadyStateResult r = c.solver->solve(c.start);
  const SteadyStateResult again = c.solver->resolve(r);
  EXPECT_LE(again.iterations, 1);
  const SteadyStateResult fresh = c.solver->solve(r.state);  // and from the quaternion state, fresh Jacobian
  EXPECT_LE(fresh.iterations, 1);
}

TEST(SteadyState, LongTransientEndsOnTheSteadyState) {
  const double U = 10.0, d = 2.0 * kDeg;
  BikeCase c = makeBike("gim", U, d);
  const SteadyStateResult r = c.solver->solve(c.start);
  // The transient from the straight run, steered at t = 0 by a hold command.
  SimTK::State s = c.start;
  SimulationSettings sim;
  sim.t_end_s = 15.0;
  sim.report_interval_s = 0;
  sim.integrator.accuracy = 1e-8;
  simulate(c.bike->getScene(), s, sim);
  const Scene& sc = c.bike->getScene();
  for (const char* out : {"chassis.yaw_rate_rad_s", "chassis.z_m", "front_axle.spin_rad_s", "rear_axle.spin_rad_s",
                          "chassis.side_slip_rad", "chassis.roll_rad"}) {
    if (!sc.hasOutput(out)) continue;
    const double vs = sc.evalOutput(out, r.state), vt = sc.evalOutput(out, s);
    std::printf("%-24s steady %.9g transient %.9g\n", out, vs, vt);
    EXPECT_NEAR(vs, vt, 1e-5 * std::abs(vs)) << out;
  }
}

TEST(SteadyState, StabilityVerdictFindsTheLinearCriticalSpeed) {
  // a > b with equal axle stiffnesses: the bicycle oversteers, and the linear
  // bicycle is unstable above U_crit = sqrt(L^2 C / (M (a - b))).
  BikeCase probe = makeBike("linear", 10.0, 0.01 * kDeg);
  const LinearBicycleParams lin = linearOf(*probe.bike);
  ASSERT_GT(lin.front_axle_to_com_m, lin.rear_axle_to_com_m);
  const double Ucrit = std::sqrt(-lin.wheelbase_m() / lin.understeerGradient());
  std::printf("linear critical speed %.3f m/s\n", Ucrit);
  for (double f : {0.9, 1.1}) {
    BikeCase c = makeBike("linear", f * Ucrit, 0.01 * kDeg);
    const SteadyStateResult r = c.solver->solve(c.start);
    const StabilityResult st = c.solver->calcStability(r);
    std::printf("U = %.2f m/s: %s, least-damped eigenvalue %.4g %+.4gi (residual %.1e)\n", f * Ucrit,
                st.stable ? "stable" : "unstable", st.least_damped.real(), st.least_damped.imag(),
                st.equilibrium_residual);
    EXPECT_EQ(st.stable, f < 1) << f;
    EXPECT_LE(st.equilibrium_residual, 1e-6);
  }
}

TEST(SteadyState, ContinuationInSpeedTakesFewIterations) {
  BikeCase c = makeBike("gim", 5.0, 0.5 * kDeg);
  std::vector<double> speeds;
  for (double U = 5; U <= 30.01; U += 2.5) speeds.push_back(U);
  const auto pts = followSteadyState(*c.solver, c.start, speeds,
                                     [&](SimTK::State& s, double U) { c.speed->setSpeed(s, U); });
  std::vector<int> its;
  for (const auto& p : pts) {
    ASSERT_TRUE(p.converged) << p.value << ": " << p.failure;
    its.push_back(p.result.iterations);
    EXPECT_NEAR(c.bike->getScene().evalOutput("chassis.forward_speed_m_s", p.result.state),
                p.value * std::cos(c.bike->getScene().evalOutput("chassis.side_slip_rad", p.result.state)), 1e-8);
  }
  std::sort(its.begin() + 1, its.end());
  EXPECT_LE(its[1 + (its.size() - 1) / 2], 4);  // median after the first point
}

TEST(SteadyState, SensitivityOfYawRateToSteeringMatchesTheClosedForm) {
  const double U = 10.0, d = 0.5 * kDeg;
  BikeCase c = makeBike("linear", U, d);
  const SteadyStateResult r = c.solver->solve(c.start);
  const auto dr = calcSteadyStateSensitivity(
      *c.solver, r, d, 1.0 * kDeg, [&](SimTK::State&, double v) { c.steer->setAngle(v); },
      [&](const SimTK::State& s) { return std::vector<double>{c.bike->getScene().evalOutput("chassis.yaw_rate_rad_s", s)}; });
  const LinearBicycleParams lin = linearOf(*c.bike);
  const double closed = calcLinearSteadyYawRate(lin, U, 1.0, 0);
  std::printf("d r / d delta = %.6f (closed form %.6f)\n", dr[0], closed);
  EXPECT_NEAR(dr[0], closed, 0.01 * closed);
  EXPECT_DOUBLE_EQ(c.steer->getAngle(), d);  // the nominal condition is restored
}

TEST(SteadyState, ImpossibleConditionIsReportedNotReturned) {
  // 30 m/s with 10 deg of steering asks for 2.4 g of lateral acceleration on
  // tires with mu <= 0.8.
  BikeCase c = makeBike("gim", 30.0, 10.0 * kDeg);
  const std::string msg = errorOf([&] { c.solver->solve(c.start); });
  EXPECT_NE(msg.find("steady state did not converge"), std::string::npos) << msg;
  EXPECT_NE(msg.find("worst equation"), std::string::npos) << msg;
}

TEST(SteadyState, ProblemErrorsAreNamed) {
  BikeCase c = makeBike("gim", 10.0, 0.0);
  EXPECT_NE(errorOf([&] { makeSteadyTurningProblem(c.bike->getScene(), "fork", {"front_axle"}, 0.0); })
                .find("chassis 'fork' must be on a free mobilizer"),
            std::string::npos);
  SteadyStateProblem p = makeSteadyTurningProblem(c.bike->getScene(), "chassis", {"front_axle", "rear_axle"}, 0.0);
  p.effective_u.pop_back();
  EXPECT_NE(errorOf([&] { SteadyStateSolver(c.bike->getScene(), p); }).find("must equal the number of mobilities"),
            std::string::npos);
}

// The relaxation-length tire changes transients only: the 4WS steady turn with
// it equals the steady-slip tire's, and its patch deflections sit at sigma x
// the steady slips (zdot = 0 is one of the solved equations).
TEST(SteadyState, RelaxationTireLeavesTheSteadyTurnUnchanged) {
  auto solveWith = [](const std::string& file, SteadyStateResult& out) {
    auto car = std::make_unique<WheeledVehicle>(WheeledVehicleParams::fromFile(file));
    car->addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(4.0 * kDeg));
    car->addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(1.0 * kDeg));
    car->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0));
    const Scene& sc = car->getScene();
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"}, 0.0));
    out = solver.solve(car->makeInitialState(10.0));
    return car;
  };
  SteadyStateResult plain, relaxed;
  const auto carPlain = solveWith("appendix_a.json", plain);
  const auto carRelaxed = solveWith("appendix_a_relaxation.json", relaxed);
  EXPECT_EQ(plain.state.getNZ(), 0);
  ASSERT_EQ(relaxed.state.getNZ(), 8);  // two patch deflections per tire
  for (const char* out : {"chassis.yaw_rate_rad_s", "chassis.z_m", "chassis.roll_rad", "chassis.side_slip_rad",
                          "rf.spin_rad_s", "lr.spin_rad_s", "speed_hold.force_N"}) {
    const double a = carPlain->getScene().evalOutput(out, plain.state);
    const double b = carRelaxed->getScene().evalOutput(out, relaxed.state);
    // The hold force is a multiplier: solved to the force tolerance (1e-6 N).
    const double tol = std::string(out) == "speed_hold.force_N" ? 1e-6 : 1e-9 * std::max(1.0, std::abs(a));
    EXPECT_NEAR(b, a, tol) << out;
  }
  // Lateral deflection of the RF tire = sigma_y x tan(alpha) at the steady state.
  const TireContact c = carRelaxed->tire(RF).calcContact(relaxed.state);
  const double tanAlpha = c.kinematics.vy_m_s / std::abs(c.kinematics.vx_m_s);
  EXPECT_NEAR(c.kinematics.tan_alpha, tanAlpha, 1e-9);
  EXPECT_GT(std::abs(tanAlpha), 1e-3);  // the tire is slipping: the check is not trivial
}

// The chassis acceleration outputs in App. A's steady 4 deg / 1 deg turn at
// 10 m/s, from Simbody's forward dynamics at the steady state, against steady
// circular motion's kinematics from the velocities alone (a = omega x v, omega
// the chassis' angular velocity): the path-normal acceleration is r |v_h|, the
// tangential one 0, the chassis-frame components those of omega x v.
TEST(SteadyState, ChassisAccelerationOutputsAreSteadyCircularMotions) {
  auto car = std::make_unique<WheeledVehicle>(WheeledVehicleParams::fromFile("appendix_a.json"));
  car->addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(4.0 * kDeg));
  car->addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(1.0 * kDeg));
  car->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0));
  const Scene& sc = car->getScene();
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"}, 0.0));
  SimTK::State s = solver.solve(car->makeInitialState(10.0)).state;
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  const SimTK::MobilizedBody& ch = car->chassis();
  const SimTK::Vec3 v = ch.getBodyOriginVelocity(s), w = ch.getBodyAngularVelocity(s);
  const SimTK::Vec3 a = w % v;  // steady circular motion of the c.m.
  const SimTK::Vec3 a_B = ~ch.getBodyRotation(s) * a;
  const double vh = std::hypot(v[0], v[1]);
  const double r = sc.evalOutput("chassis.yaw_rate_rad_s", s);
  EXPECT_NEAR(sc.evalOutput("chassis.path_normal_accel_m_s2", s), r * vh, 1e-8);
  EXPECT_NEAR(sc.evalOutput("chassis.path_tangential_accel_m_s2", s), 0.0, 1e-8);
  EXPECT_NEAR(sc.evalOutput("chassis.lateral_accel_m_s2", s), a_B[1], 1e-8);
  EXPECT_NEAR(sc.evalOutput("chassis.longitudinal_accel_m_s2", s), a_B[0], 1e-8);
  EXPECT_GT(r * vh, 1.0);  // 2.42 m/s^2: the check is not trivial
  std::printf("steady 10 m/s: a_n %.9f m/s^2 (r |v_h| %.9f), chassis-frame a_y %.9f, a_x %.3e\n",
              sc.evalOutput("chassis.path_normal_accel_m_s2", s), r * vh, sc.evalOutput("chassis.lateral_accel_m_s2", s),
              sc.evalOutput("chassis.longitudinal_accel_m_s2", s));
}
