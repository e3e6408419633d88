// Optimal steering ratio (plugins/steering_ratio): the linear bicycle law
// (6.1)-(6.9) against its closed form and a direct solve of the steady
// equations; the nonlinear optimum (6.12)-(6.15) on the App. A 4WS vehicle with
// linear tires against the linear law of that vehicle's own a, b, M, C; the
// optimum drives the side slip below 1e-8 rad; the fit (8.1); named errors.
#include <cmath>
#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering/steering.h"
#include "vdyn/steering_ratio/steering_ratio.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {
const double kDeg = SimTK::Pi / 180;

/// Steady (6.5)-(6.6) with beta' = r' = 0 solved as a 2 x 2 linear system
/// (Cramer), independent of the library's elimination.
void solveSteadyLinear(const LinearBicycleParams& p, double U, double df, double kr, double& beta, double& r) {
  const double M = p.mass_kg, a = p.front_axle_to_com_m, b = p.rear_axle_to_com_m;
  const double Cf = p.front_cornering_stiffness_N_per_rad, Cr = p.rear_cornering_stiffness_N_per_rad;
  // Lateral: M U r = Cf (df - beta - a r / U) + Cr (kr df - beta + b r / U)
  // Yaw:     0 = a Cf (df - beta - a r / U) - b Cr (kr df - beta + b r / U)
  const double A11 = Cf + Cr, A12 = M * U + (a * Cf - b * Cr) / U, B1 = (Cf + kr * Cr) * df;
  const double A21 = a * Cf - b * Cr, A22 = (a * a * Cf + b * b * Cr) / U, B2 = (a * Cf - b * kr * Cr) * df;
  const double det = A11 * A22 - A12 * A21;
  beta = (B1 * A22 - A12 * B2) / det;
  r = (A11 * B2 - A21 * B1) / det;
}
}  // namespace

TEST(SteeringRatio, LinearLawMatchesItsClosedFormAndTheSteadyEquations) {
  const LinearBicycleParams p = LinearBicycleParams::fromFile("ch6_linear_bicycle.json");
  EXPECT_EQ(p.mass_kg, 1024.0);
  EXPECT_EQ(p.front_cornering_stiffness_N_per_rad, 1.4e5);
  // (6.9) restated; at 12 m/s by hand: (-0.965 + 0.605507) / (1.305 + 0.447747) = -0.205102.
  EXPECT_NEAR(calcLinearOptimalRatio(p, 12.0), -0.205102, 2e-6);
  const double l = 2.27;
  for (double U : {2.0, 8.0, 14.0, 20.0, 35.0}) {
    const double closed = (-0.965 + 1024 * 1.305 * U * U / (1.4e5 * l)) / (1.305 + 1024 * 0.965 * U * U / (1.4e5 * l));
    EXPECT_NEAR(calcLinearOptimalRatio(p, U), closed, 1e-14) << U;
    for (double kr : {-0.3, 0.0, 0.4}) {
      double beta, r;
      solveSteadyLinear(p, U, 2 * kDeg, kr, beta, r);
      EXPECT_NEAR(calcLinearSteadySideSlip(p, U, 2 * kDeg, kr), beta, 1e-13) << U << ' ' << kr;
      EXPECT_NEAR(calcLinearSteadyYawRate(p, U, 2 * kDeg, kr), r, 1e-13) << U << ' ' << kr;
    }
    // The optimal ratio zeroes the steady side slip of the 2 x 2 solve.
    double beta, r;
    solveSteadyLinear(p, U, 2 * kDeg, calcLinearOptimalRatio(p, U), beta, r);
    EXPECT_NEAR(beta, 0.0, 1e-15) << U;
  }
  // Contra phase below the zero crossing, in phase above (6.9).
  const double U0 = calcLinearZeroRatioSpeed(p);
  EXPECT_NEAR(U0, std::sqrt(0.965 * 1.4e5 * l / (1024 * 1.305)), 1e-12);
  EXPECT_NEAR(calcLinearOptimalRatio(p, U0), 0.0, 1e-14);
  EXPECT_LT(calcLinearOptimalRatio(p, U0 - 1), 0);
  EXPECT_GT(calcLinearOptimalRatio(p, U0 + 1), 0);
}

TEST(SteeringRatio, FitRecoversAQuadraticAndTheTableRoundTrips) {
  std::vector<double> d, k;
  for (double x = 0.25; x <= 3.0; x += 0.25) {
    d.push_back(x);
    k.push_back(0.12 - 0.004 * x * x + (d.size() % 2 ? 1e-4 : -1e-4));
  }
  const RatioFit f = fitRatio(20.0, d, k);
  EXPECT_NEAR(f.c1, 0.12, 1e-4);
  EXPECT_NEAR(f.c2_per_deg2, -0.004, 2e-5);
  EXPECT_NEAR(f.rms_residual, 1e-4, 2e-5);
  EXPECT_EQ(f.points, int(d.size()));
  EXPECT_EQ(f.front_max_deg, 3.0);  // the largest |front angle| fitted
  EXPECT_EQ(fitRatio(12, {1, -5.5, 3}, {0.1, 0.3, 0.2}).front_max_deg, 5.5);
  RatioFit g = f;
  g.speed_m_s = 6.0;
  const std::string text = formatRatioTable({f, g});
  EXPECT_EQ(text.substr(0, 43), "{\n  \"delta_f_unit\": \"deg\",\n  \"fit\": [\n    {");
  EXPECT_LT(text.find("\"speed_m_s\""), text.find("\"c1\""));  // the documented key order
  EXPECT_LT(text.find("\"rms_residual\""), text.find("\"points\""));
  EXPECT_LT(text.find("\"points\""), text.find("\"front_max_deg\""));
  const Json t = Json::parse(text);
  EXPECT_EQ(t["delta_f_unit"], "deg");
  EXPECT_EQ(t["fit"][0]["speed_m_s"], 6.0);  // ascending
  const std::string path = ::testing::TempDir() + "kr_table_test.json";
  std::ofstream(path) << "// comment line\n" << text;
  const auto back = readRatioTable(path);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].c2_per_deg2, f.c2_per_deg2);
  EXPECT_EQ(back[1].points, f.points);
  EXPECT_EQ(back[1].front_max_deg, 3.0);
  EXPECT_EQ(formatRatioTable({RatioFit{12.0}}).find("front_max_deg"), std::string::npos);  // not recorded: no key
}

TEST(SteeringRatio, ErrorsNameTheFieldAndValue) {
  LinearBicycleParams p;
  p.mass_kg = -1;
  EXPECT_EQ(errorOf([&] { p.validate(); }), "linear bicycle mass_kg must be positive, got -1");
  EXPECT_EQ(errorOf([&] { calcLinearOptimalRatio(LinearBicycleParams{}, -1.0); }), "linear bicycle speed_m_s must not be negative, got -1");
  EXPECT_EQ(errorOf([] { fitRatio(12.0, {1.0, -1.0}, {0.1, 0.2}); }),
            "ratio fit at 12 m/s needs at least 2 distinct front angles, got 1");
  EXPECT_EQ(errorOf([] { fitRatio(12.0, {1.0, 2.0}, {0.1}); }), "ratio fit at 12 m/s: 2 front angles but 1 ratios");
  EXPECT_EQ(errorOf([] { formatRatioTable({RatioFit{12.0}, RatioFit{12.0}}); }),
            "ratio table: speed_m_s 12 appears twice");
  const std::string path = ::testing::TempDir() + "kr_table_bad.json";
  std::ofstream(path) << R"({"delta_f_unit": "rad", "fit": []})";
  EXPECT_NE(errorOf([&] { readRatioTable(path); }).find("delta_f_unit: expected \"deg\", got \"rad\""),
            std::string::npos);
}

namespace {
/// The App. A vehicle with linear tires, front and rear held, speed held.
struct LinearFourWs {
  std::unique_ptr<WheeledVehicle> car;
  std::shared_ptr<HoldCommand> front = std::make_shared<HoldCommand>(0.0);
  std::shared_ptr<HoldCommand> rear = std::make_shared<HoldCommand>(0.0);
  std::unique_ptr<SteadyStateSolver> solver;
  SteadyStateResult straight;
  LinearBicycleParams lin;  // the vehicle's own linear bicycle

  explicit LinearFourWs(double U) {
    WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a.json");
    for (AxleParams& a : p.axles) a.tire = a.tire.linearised();
    car = std::make_unique<WheeledVehicle>(p);
    car->addAxleSteering("front_steer", "front", front);
    car->addAxleSteering("rear_steer", "rear", rear);
    const auto& hold = static_cast<const SpeedHoldPlugin&>(
        car->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", U)));
    const Scene& sc = car->getScene();
    solver = std::make_unique<SteadyStateSolver>(
        sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"}, 0.0));
    SimTK::State s = car->makeInitialState(U);
    hold.setSpeed(s, U);
    straight = solver->solve(s);
    // a, b from the whole vehicle's centre of mass and the wheel centres.
    const SimTK::SimbodyMatterSubsystem& m = sc.getMatter();
    const SimTK::Vec3 com = m.calcSystemMassCenterLocationInGround(straight.state);
    // The wheel bodies by name: every template (and formulation) has them.
    auto wheelX = [&](int c) {
      return sc.getBody(car->cornerName(c) + ".wheel").getBodyOriginLocation(straight.state)[0];
    };
    lin.mass_kg = car->totalMass();
    lin.front_axle_to_com_m = 0.5 * (wheelX(RF) + wheelX(LF)) - com[0];
    lin.rear_axle_to_com_m = com[0] - 0.5 * (wheelX(RR) + wheelX(LR));
    lin.front_cornering_stiffness_N_per_rad = lin.rear_cornering_stiffness_N_per_rad =
        2 * p.axles[0].tire.getNumber("cornering_stiffness_N_per_rad");
  }
  SetSteering steer() {
    return [this](SimTK::State&, double f, double r) {
      front->setAngle(f);
      rear->setAngle(r);
    };
  }
  /// Side slip at the whole vehicle's centre of mass (the linear bicycle's point).
  SideSlipOf comSlip() const {
    return [this](const SimTK::State& s) {
      // A copied State comes back below Stage::Velocity: realize it as
      // Scene::evalOutput does.
      const SimTK::SimbodyMatterSubsystem& m = car->getScene().getMatter();
      if (s.getSystemStage() < SimTK::Stage::Velocity) car->getScene().getSystem().realize(s, SimTK::Stage::Velocity);
      SimTK::Vec3 v(0);
      for (SimTK::MobilizedBodyIndex i(1); i < m.getNumBodies(); ++i) {
        const SimTK::MobilizedBody& b = m.getMobilizedBody(i);
        v += b.getBodyMass(s) * b.findStationVelocityInGround(s, b.getBodyMassCenterStation(s));
      }
      const SimTK::Rotation& R = car->chassis().getBodyRotation(s);
      return std::atan2(SimTK::dot(v, R.y()), SimTK::dot(v, R.x()));
    };
  }
};
}  // namespace

TEST(SteeringRatio, NonlinearOptimumOfTheLinearTireVehicleIsTheLinearLaw) {
  for (double U : {22.0, 8.0}) {
    LinearFourWs v(U);
    const double krLin = calcLinearOptimalRatio(v.lin, U);
    OptimalRatioOptions o;
    o.check_stability = false;
    const OptimalRatioPoint pt =
        solveOptimalRatio(*v.solver, v.straight, 0.5 * kDeg, 0.0, v.steer(), v.comSlip(), o);
    std::printf("U %g m/s: a %.4f b %.4f M %.1f; Kr nonlinear %.6f linear %.6f; beta %.3e; %d Kr iterations, %d solves, "
                "%d Newton iterations\n",
                U, v.lin.front_axle_to_com_m, v.lin.rear_axle_to_com_m, v.lin.mass_kg, pt.kr, krLin, pt.side_slip_rad,
                pt.kr_iterations, pt.solves, pt.newton_iterations);
    ASSERT_EQ(pt.status, OptimalRatioStatus::ZeroSideSlip) << pt.failure;
    EXPECT_LT(std::abs(pt.side_slip_rad), 1e-8);
    EXPECT_LT(std::abs(v.comSlip()(pt.result.state)), 1e-8);
    // The suspension (roll steer, camber, load transfer) is the only
    // nonlinearity left at 0.5 deg: within 0.01 of Kr (0.004 measured).
    EXPECT_NEAR(pt.kr, krLin, 0.01);
    // The rear angle in the solution is Kr delta_f.
    EXPECT_DOUBLE_EQ(v.rear->getAngle(), pt.kr * 0.5 * kDeg);
  }
}

TEST(SteeringRatio, ContinuationInFrontAngleKeepsSideSlipZero) {
  const double U = 20.0;
  LinearFourWs v(U);
  const SideSlipOf chassisSlip = [&](const SimTK::State& s) {
    return v.car->getScene().evalOutput("chassis.side_slip_rad", s);
  };
  const auto pts = followOptimalRatio(*v.solver, v.straight, {0.25 * kDeg, 0.5 * kDeg, 0.75 * kDeg, 1.0 * kDeg},
                                      calcLinearOptimalRatio(v.lin, U), v.steer(), chassisSlip);
  ASSERT_EQ(pts.size(), 4u);
  for (const auto& p : pts) {
    ASSERT_EQ(p.status, OptimalRatioStatus::ZeroSideSlip) << p.failure;
    EXPECT_TRUE(p.stable);
    EXPECT_LT(std::abs(p.side_slip_rad), 1e-8);
    EXPECT_LT(std::abs(chassisSlip(p.result.state)), 1e-8);
    std::printf("front %.2f deg: Kr %.6f, %d Kr iterations, %d solves\n", p.front_rad / kDeg, p.kr, p.kr_iterations,
                p.solves);
  }
  // With linear tires Kr hardly depends on the angle.
  EXPECT_NEAR(pts.back().kr, pts.front().kr, 0.01);
  // Bad input is named.
  EXPECT_EQ(errorOf([&] {
              followOptimalRatio(*v.solver, v.straight, {1.0 * kDeg, 0.5 * kDeg}, 0.0, v.steer(), chassisSlip);
            }).substr(0, 40),
            "optimal ratio front angles must ascend: ");
  OptimalRatioOptions bad;
  bad.max_kr_step = 0;
  EXPECT_EQ(errorOf([&] { solveOptimalRatio(*v.solver, v.straight, 0.01, 0.0, v.steer(), chassisSlip, bad); }),
            "optimal ratio max_kr_step must be positive, got 0");
}

TEST(SteeringRatio, GimTireBranchEndsWithAdmissiblePointsOnly) {
  // The App. A vehicle as built (Gim tires) at 25 m/s: steady states exist only
  // up to about 2 deg of front angle. Every point before the end has zero side
  // slip (or is flagged), is stable where checked, and the end is located
  // between two front angles by bisection (inserted points ascend).
  const double U = 25.0;
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a.json");
  WheeledVehicle car(p);
  auto front = std::make_shared<HoldCommand>(0.0), rear = std::make_shared<HoldCommand>(0.0);
  car.addAxleSteering("front_steer", "front", front);
  car.addAxleSteering("rear_steer", "rear", rear);
  const auto& hold = static_cast<const SpeedHoldPlugin&>(
      car.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", U)));
  const Scene& sc = car.getScene();
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"}, 0.0));
  SimTK::State s = car.makeInitialState(U);
  hold.setSpeed(s, U);
  const SteadyStateResult straight = solver.solve(s);
  const SetSteering steer = [&](SimTK::State&, double f, double r) {
    front->setAngle(f);
    rear->setAngle(r);
  };
  const SideSlipOf slip = [&](const SimTK::State& st) { return sc.evalOutput("chassis.side_slip_rad", st); };
  OptimalRatioOptions o;
  o.max_bisections = 2;
  const auto pts = followOptimalRatio(solver, straight, {1.5 * kDeg, 2.0 * kDeg, 2.5 * kDeg, 3.0 * kDeg}, 0.5, steer, slip, o);
  ASSERT_GE(pts.size(), 4u);
  int reached = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto& q = pts[i];
    std::printf("front %.4f deg: %s Kr %.5f beta %.3e stable %d\n", q.front_rad / kDeg, toString(q.status), q.kr,
                q.side_slip_rad, q.stable);
    if (i > 0) {
      EXPECT_GT(q.front_rad, pts[i - 1].front_rad);
    }
    if (q.status == OptimalRatioStatus::NoSteadyState) continue;
    ++reached;
    EXPECT_TRUE(q.stable);
    if (q.status == OptimalRatioStatus::ZeroSideSlip) {
      EXPECT_LT(std::abs(slip(q.result.state)), 1e-8);
    } else {
      EXPECT_FALSE(q.failure.empty());
    }
  }
  EXPECT_GE(reached, 2);
  // The requested 1.5 and 2 deg are reached (by halving the first step from 0).
  for (const auto& q : pts)
    if (std::abs(q.front_rad - 1.5 * kDeg) < 1e-12 || std::abs(q.front_rad - 2.0 * kDeg) < 1e-12) {
      EXPECT_EQ(q.status, OptimalRatioStatus::ZeroSideSlip) << q.front_rad / kDeg << ": " << q.failure;
    }
  EXPECT_EQ(pts.back().status, OptimalRatioStatus::NoSteadyState);  // 3 deg is beyond the branch at 25 m/s
  // In phase at 25 m/s, and growing with the front angle (tire saturation).
  EXPECT_GT(pts[0].kr, 0.4);
  EXPECT_GT(pts[1].kr, pts[0].kr);
}
