// Pseudo-arclength continuation (plugins/steady_state/arclength.h): closed
// forms with a known fold (x1^2 + lambda = 0) and a known Hopf point (the
// Hopf normal form, eigenvalues lambda +- i), passing through the fold, the
// step control and its named minimum-step error; on the bicycle with
// saturating tires, the fold in the front steering angle against the limit
// that natural-parameter continuation finds (the last converged point), and
// the unstable branch past it.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steady_state/arclength.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steady_state/straight_start.h"
#include "vdyn/steering/steering.h"
#include "vdyn/vehicles/bicycle.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {
/// F = [x1^2 + lambda, x2 - x1]: a fold at lambda = 0, x = 0; the dynamics
/// x' = -F have eigenvalues -2 x1 and -1 (stable for x1 > 0).
ArclengthSystem foldSystem() {
  ArclengthSystem s;
  s.x_scale = Eigen::VectorXd::Ones(2);
  s.lambda_scale = 1;
  s.residual = [](const Eigen::VectorXd& x, double l) {
    Eigen::VectorXd r(2);
    r << x[0] * x[0] + l, x[1] - x[0];
    return r;
  };
  s.jacobian = [](const Eigen::VectorXd& x, double, const Eigen::VectorXd&) {
    Eigen::MatrixXd J(2, 3);
    J << 2 * x[0], 0, 1, -1, 1, 0;
    return J;
  };
  s.converged = [](const Eigen::VectorXd& r) { return r.lpNorm<Eigen::Infinity>() <= 1e-12; };
  s.eigenvalues = [](const Eigen::VectorXd& x, double) {
    return std::vector<std::complex<double>>{-2 * x[0], -1.0};
  };
  return s;
}
}  // namespace

TEST(Arclength, PassesThroughTheFoldOfX2PlusLambdaAndLocatesIt) {
  ArclengthOptions o;
  o.step = 0.05;
  o.max_step = 0.2;
  o.location_tolerance = 1e-8;
  o.max_points = 60;
  o.lambda_min = -1.0001;  // the lower branch ends at lambda = -1 again
  Eigen::VectorXd x0(2);
  x0 << 1, 1;
  const ArclengthResult r = continueArclength(foldSystem(), x0, -1.0, o);
  ASSERT_EQ(r.special.size(), 1u);
  const ArclengthSpecialPoint& f = r.special[0];
  std::printf("fold at lambda %.3e, x1 %.3e (bracket %.2e, %d location iterations); %d steps, %d rejected, %d "
              "corrector iterations, stop %s\n",
              f.point.lambda, f.point.x[0], f.bracket_length, f.location_iterations, r.steps, r.rejected_steps,
              r.corrector_iterations, r.stop_reason.c_str());
  EXPECT_EQ(f.kind, "fold");
  EXPECT_TRUE(f.located);
  EXPECT_LE(f.bracket_length, 1e-8);
  EXPECT_LE(std::abs(f.point.lambda), 1e-8);
  EXPECT_LE(std::abs(f.point.x[0]), 1e-8);
  EXPECT_LE(std::abs(f.point.eigenvalues.front().real()), 2e-8);  // the real eigenvalue -2 x1 crosses 0
  EXPECT_EQ(r.stop_reason, "lambda_range");
  // Points on both sides of the fold, each on the curve, stable above it.
  int upper = 0, lower = 0;
  for (const auto& p : r.points) {
    EXPECT_NEAR(p.lambda, -p.x[0] * p.x[0], 1e-11);
    EXPECT_LE(p.lambda, 1e-12);
    if (p.x[0] > 0) {
      ++upper;
      EXPECT_TRUE(p.stable);
      EXPECT_GT(p.fold_test(), 0);  // lambda increases along the upper branch
    } else if (p.x[0] < 0) {
      ++lower;
      EXPECT_FALSE(p.stable);
      EXPECT_LT(p.fold_test(), 0);
    }
  }
  EXPECT_GE(upper, 3);
  EXPECT_GE(lower, 3);
  EXPECT_LT(r.points.back().x[0], -0.99);  // back to lambda = -1 on the lower branch
}

TEST(Arclength, LocatesTheHopfPointOfTheNormalForm) {
  // x' = lambda x - y - x (x^2 + y^2), y' = x + lambda y - y (x^2 + y^2): the
  // origin's eigenvalues are lambda +- i, a Hopf point at lambda = 0.
  ArclengthSystem s;
  s.x_scale = Eigen::VectorXd::Ones(2);
  s.lambda_scale = 1;
  s.residual = [](const Eigen::VectorXd& x, double l) {
    const double q = x.squaredNorm();
    Eigen::VectorXd r(2);
    r << l * x[0] - x[1] - x[0] * q, x[0] + l * x[1] - x[1] * q;
    return r;
  };
  s.jacobian = [](const Eigen::VectorXd& x, double l, const Eigen::VectorXd&) {
    const double a = x[0], b = x[1], q = a * a + b * b;
    Eigen::MatrixXd J(2, 3);
    J << l - q - 2 * a * a, -1 - 2 * a * b, a, 1 - 2 * a * b, l - q - 2 * b * b, b;
    return J;
  };
  s.converged = [](const Eigen::VectorXd& r) { return r.lpNorm<Eigen::Infinity>() <= 1e-12; };
  s.eigenvalues = [](const Eigen::VectorXd&, double l) {
    return std::vector<std::complex<double>>{{l, 1.0}, {l, -1.0}};
  };
  ArclengthOptions o;
  o.step = 0.01;
  o.max_step = 0.1;
  o.location_tolerance = 1e-9;
  o.lambda_max = 1;
  const ArclengthResult r = continueArclength(s, Eigen::VectorXd::Zero(2), -1.0, o);
  ASSERT_EQ(r.special.size(), 1u);
  const ArclengthSpecialPoint& h = r.special[0];
  std::printf("Hopf at lambda %.3e (bracket %.2e, %d iterations); %d steps from -1 to %.3f\n", h.point.lambda,
              h.bracket_length, h.location_iterations, r.steps, r.points.back().lambda);
  EXPECT_EQ(h.kind, "hopf");
  EXPECT_TRUE(h.located);
  EXPECT_LE(std::abs(h.point.lambda), 1e-9);
  EXPECT_NEAR(std::abs(h.point.eigenvalues.front().imag()), 1.0, 1e-12);
  // The corrector needs no iteration on this linear branch: the step grows
  // from 0.01 to max_step 0.1, so far fewer than 200 steps of 0.01 reach 1.
  EXPECT_LE(r.steps, 30);
  EXPECT_EQ(r.stop_reason, "lambda_range");
  for (const auto& p : r.points) EXPECT_EQ(p.stable, p.lambda < -1e-6) << p.lambda;
}

TEST(Arclength, AStepBelowTheMinimumIsANamedError) {
  // F = x - lambda, undefined (NaN) for lambda > 0.5: no step passes 0.5.
  ArclengthSystem s;
  s.x_scale = Eigen::VectorXd::Ones(1);
  s.residual = [](const Eigen::VectorXd& x, double l) {
    return Eigen::VectorXd::Constant(1, l > 0.5 ? NAN : x[0] - l);
  };
  s.jacobian = [](const Eigen::VectorXd&, double, const Eigen::VectorXd&) {
    Eigen::MatrixXd J(1, 2);
    J << 1, -1;
    return J;
  };
  s.converged = [](const Eigen::VectorXd& r) { return std::abs(r[0]) <= 1e-12; };
  ArclengthOptions o;
  o.step = 0.1;
  o.min_step = 1e-4;
  const std::string msg = errorOf([&] { continueArclength(s, Eigen::VectorXd::Zero(1), 0.0, o); });
  std::printf("%s\n", msg.c_str());
  EXPECT_NE(msg.find("the step fell below min_step = 0.0001"), std::string::npos) << msg;
  EXPECT_NE(msg.find("non-finite residual"), std::string::npos) << msg;
}

namespace {
const double kDeg = SimTK::Pi / 180;
}

// The bicycle (a > b: oversteering) with saturating GIM tires at 20 m/s: the
// steady state continued in the front steering angle has a fold (the largest
// angle with a steady turn). Natural-parameter continuation in 0.5 deg steps
// (followSteadyState, the old limit: the last converged point) ends within a
// step below it; pseudo-arclength continuation passes it onto the unstable
// branch (a real eigenvalue > 0).
TEST(Arclength, BicycleFoldInSteeringAgreesWithTheLastConvergedPointAndPassesIt) {
  const double U = 20.0;
  BicycleParams p = BicycleParams::fromFile("bicycle.json");
  p.tire.plugin = "gim";
  Bicycle bike(p);
  auto steer = std::make_shared<HoldCommand>(0.0);
  bike.addFrontSteering("front_steer", steer);
  bike.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", U));
  const Scene& sc = bike.getScene();
  const SimTK::State start = bike.makeInitialState(U);
  SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"front_axle", "rear_axle"}, 0.0));
  auto setSteer = [&](SimTK::State&, double d) { steer->setAngle(d); };
  // The old limit: natural-parameter continuation, 0.5 deg steps.
  std::vector<double> grid;
  for (int i = 0; i <= 60; ++i) grid.push_back(i * 0.5 * kDeg);
  const auto nat = followSteadyState(solver, start, grid, setSteer);
  int lastOk = -1;
  while (lastOk + 1 < int(nat.size()) && nat[lastOk + 1].converged) ++lastOk;
  ASSERT_GE(lastOk, 2);
  ASSERT_LT(lastOk + 1, int(nat.size())) << "no limit below 30 deg";
  const double oldLimit = grid[lastOk];

  ArclengthOptions o;
  o.step = 0.25 * kDeg;
  o.max_step = 1.0 * kDeg;
  o.min_step = 1e-6 * kDeg;
  o.location_tolerance = 1e-6 * kDeg;
  o.max_points = 80;
  o.stop_after_folds = 1;
  o.points_after_last_fold = 3;
  const ArclengthResult r = continueSteadyState(solver, nat[1].result, grid[1], setSteer, kDeg, true, o);
  ASSERT_FALSE(r.special.empty());
  const ArclengthSpecialPoint* fold = nullptr;
  for (const auto& s : r.special)
    if (s.kind == "fold" && !fold) fold = &s;
  ASSERT_NE(fold, nullptr);
  const SteadyStateResult at = solver.makeDrivenResult(fold->point.x, fold->point.lambda);
  const double ay = sc.evalOutput("chassis.yaw_rate_rad_s", at.state) * U;
  std::printf("bicycle %g m/s: fold at front steer %.6f deg (a_y ~ %.4f m/s^2; bracket %.1e deg, %d location "
              "iterations), least eigenvalue %.3e; old limit (last converged, 0.5 deg grid) %.2f deg; %d steps, %d "
              "rejected, %d corrector iterations, %d Jacobians, %d residuals, %d quasi-Newton fallbacks\n",
              U, fold->point.lambda / kDeg, ay, fold->bracket_length / kDeg, fold->location_iterations,
              fold->point.eigenvalues.front().real(), oldLimit / kDeg, r.steps, r.rejected_steps,
              r.corrector_iterations, r.jacobians, r.residual_evaluations, r.quasi_newton_fallbacks);
  EXPECT_TRUE(fold->located);
  EXPECT_GE(fold->point.lambda, oldLimit);
  EXPECT_LT(fold->point.lambda, oldLimit + 0.5 * kDeg);
  EXPECT_LE(std::abs(fold->point.eigenvalues.front().real()), 0.05);  // the real eigenvalue crosses 0 here
  // Stable before the fold, unstable past it (a real eigenvalue > 0).
  int before = 0, past = 0;
  for (const auto& q : r.points) {
    if (q.s < fold->point.s) {
      ++before;
      EXPECT_TRUE(q.stable) << q.lambda / kDeg;
    } else {
      ++past;
      EXPECT_GT(q.eigenvalues.front().real(), 0) << q.lambda / kDeg;
      EXPECT_LT(q.lambda, fold->point.lambda);
      EXPECT_LT(q.fold_test(), 0);
    }
  }
  EXPECT_GE(before, 3);
  EXPECT_GE(past, 3);
}

// The steady state on the branch from straight running (solveFromStraightRunning:
// the command time continued from 0): the GIM bicycle at 20 m/s with a smooth
// step of the front angle. At 1 deg it is the direct solve's state (to the
// solver's precision); at 3 deg, past the fold in steering (1.851124 deg,
// found above by continuation in a held angle), it is the named error with the
// fold's front angle, found here by a homotopy in time instead.
TEST(Arclength, SteadyStateFromStraightRunningStopsAtTheFold) {
  const double U = 20.0;
  auto solveWith = [&](double finalDeg, bool straight) {
    BicycleParams p = BicycleParams::fromFile("bicycle.json");
    p.tire.plugin = "gim";
    Bicycle bike(p);
    bike.addFrontSteering("front_steer", std::make_shared<SmoothStepCommand>(0.0, finalDeg * kDeg, 0.5, 1.0));
    bike.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", U));
    const Scene& sc = bike.getScene();
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"front_axle", "rear_axle"}, 1.5));
    const SimTK::State start = bike.makeInitialState(U);
    StraightStartReport rep;
    const SteadyStateResult r =
        straight ? solveFromStraightRunning(
                       solver, sc, start,
                       [&sc](const SimTK::State& s) { return sc.evalOutput("front_steer.command_rad", s); }, &rep)
                 : solver.solve(start);
    if (straight) std::printf("  %g deg: %d homotopy steps, %d rejected\n", finalDeg, rep.arclength_steps, rep.rejected_steps);
    return sc.evalOutput("chassis.yaw_rate_rad_s", r.state);
  };
  const double rs = solveWith(1.0, true), rd = solveWith(1.0, false);
  std::printf("1 deg: yaw rate from straight running %.12f, direct %.12f (difference %.1e)\n", rs, rd, rs - rd);
  EXPECT_NEAR(rs, rd, 1e-9 * rd);
  EXPECT_GT(rs, 0);
  const std::string msg = errorOf([&] { solveWith(3.0, true); });
  std::printf("3 deg: %s\n", msg.c_str());
  const std::string head = "no steady state on the branch from straight running: fold at front steer ";
  ASSERT_EQ(msg.rfind(head, 0), 0u) << msg;
  const double foldDeg = std::stod(msg.substr(head.size()));
  EXPECT_NEAR(foldDeg, 1.851124, 1e-5);
  EXPECT_NE(msg.find("lateral acceleration 6.74"), std::string::npos) << msg;
}

// The quasi-Newton corrector (the start's Jacobian with Broyden updates)
// against Newton with a fresh Jacobian at every iteration, on a smooth curved
// branch, F = [x1^3 + x1 - lambda, x2 - sin(3 x1)] from lambda = -3 to 3:
// every point of both runs is a solution to the same tolerance, both reach the
// end, and the quasi-Newton run takes the tangents' Jacobians and few more
// (one per accepted step, the start's, and those of the steps Newton retried).
TEST(Arclength, QuasiNewtonCorrectorMeetsTheSameTolerancesWithFewerJacobians) {
  ArclengthSystem s;
  s.x_scale = Eigen::VectorXd::Ones(2);
  s.lambda_scale = 1;
  s.residual = [](const Eigen::VectorXd& x, double l) {
    Eigen::VectorXd r(2);
    r << x[0] * x[0] * x[0] + x[0] - l, x[1] - std::sin(3 * x[0]);
    return r;
  };
  s.jacobian = [](const Eigen::VectorXd& x, double, const Eigen::VectorXd&) {
    Eigen::MatrixXd J(2, 3);
    J << 3 * x[0] * x[0] + 1, 0, -1, -3 * std::cos(3 * x[0]), 1, 0;
    return J;
  };
  s.converged = [](const Eigen::VectorXd& r) { return r.lpNorm<Eigen::Infinity>() <= 1e-12; };
  ArclengthOptions o;
  o.step = 0.05;
  o.max_step = 0.5;
  o.lambda_max = 3;
  Eigen::VectorXd x0(2);
  const double x1 = -1.2134116627622296;  // x1^3 + x1 = -3
  x0 << x1, std::sin(3 * x1);
  ASSERT_LE(s.residual(x0, -3.0).lpNorm<Eigen::Infinity>(), 1e-12);
  ArclengthOptions on = o;
  on.quasi_newton = false;
  const ArclengthResult q = continueArclength(s, x0, -3.0, o), n = continueArclength(s, x0, -3.0, on);
  std::printf("quasi-Newton: %d steps, %d rejected, %d Jacobians, %d residuals, %d fallbacks; Newton: %d steps, %d "
              "rejected, %d Jacobians, %d residuals\n",
              q.steps, q.rejected_steps, q.jacobians, q.residual_evaluations, q.quasi_newton_fallbacks, n.steps,
              n.rejected_steps, n.jacobians, n.residual_evaluations);
  for (const ArclengthResult* r : {&q, &n}) {
    EXPECT_EQ(r->stop_reason, "lambda_range");
    EXPECT_GT(r->points.back().lambda, 3.0);
    for (const auto& p : r->points) EXPECT_LE(s.residual(p.x, p.lambda).lpNorm<Eigen::Infinity>(), 1e-12);
  }
  EXPECT_EQ(n.quasi_newton_fallbacks, 0);
  EXPECT_EQ(n.jacobians, n.steps + 1 + n.corrector_iterations);  // a tangent per point, one per Newton iteration
  // Every Jacobian beyond one per tangent is a Newton retry's.
  EXPECT_GE(q.jacobians, q.steps + 1);
  EXPECT_LE(q.jacobians - (q.steps + 1), o.max_corrector_iterations * q.quasi_newton_fallbacks);
  EXPECT_LT(q.jacobians, n.jacobians / 2);
}
