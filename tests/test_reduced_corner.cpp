// The reduced corner model (vehicles/reduced_wishbone.h) against the
// constrained one: loop closure and steering angle exact by construction,
// H and HDot and the arm rows by finite differences, the same ch3 steady
// state (steady-state solver on both), the same transient and the same mixed
// sensitivity.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "test_util.h"
#include "vdyn/core/simulation.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steady_state/steady_state.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {
const double kDeg = SimTK::Pi / 180;

WheeledVehicleParams params(const std::string& model, const std::string& file = "appendix_a.json") {
  WheeledVehicleParams p = WheeledVehicleParams::fromFile(file);
  p.formulation = model;  // "constrained" or "reduced" (rows Simbody's; "dense" switches them, useDenseRows)
  return p;
}

/// The chapter 3 manoeuvre: smooth steps 4 deg front, 1 deg rear from 0.5 s over 1 s, 10 m/s.
std::unique_ptr<WheeledVehicle> ch3Car(const std::string& model, const std::string& file, bool hold) {
  auto car = std::make_unique<WheeledVehicle>(params(model, file));
  if (hold) {
    car->addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(4 * kDeg));
    car->addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(1 * kDeg));
  } else {
    car->addAxleSteering("front_steer", "front", std::make_shared<SmoothStepCommand>(0, 4 * kDeg, 0.5, 1.0));
    car->addAxleSteering("rear_steer", "rear", std::make_shared<SmoothStepCommand>(0, 1 * kDeg, 0.5, 1.0));
  }
  car->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0));
  return car;
}

/// The two corner models compared throughout.
const char* const kModels[2] = {"constrained", "reduced"};


double vee(const SimTK::Mat33& W, int i) {
  return i == 0 ? 0.5 * (W(2, 1) - W(1, 2)) : i == 1 ? 0.5 * (W(0, 2) - W(2, 0)) : 0.5 * (W(1, 0) - W(0, 1));
}

/// The integrator of the ch3 comparisons: accuracy 1e-8, constraint tolerance 1e-10, to t_end_s.
SimulationSettings ch3Simulation(double t_end_s) {
  SimulationSettings sim;
  sim.t_end_s = t_end_s;
  sim.integrator.accuracy = 1e-8;
  sim.integrator.constraint_tolerance = 1e-10;
  return sim;
}

/// Runs `sa` in scene `a` and `sb` in scene `b` for 2.5 s of the ch3 manoeuvre
/// (sampled every 0.05 s) and expects the same yaw rate, roll and front
/// steering angle histories: max difference < 1e-6 x the first run's peak,
/// each peak > 1e-3 (the vehicle is turning: the comparison is not trivial).
void expectSameCh3Transient(const Scene& a, SimTK::State& sa, const Scene& b, SimTK::State& sb) {
  SimulationSettings sim = ch3Simulation(2.5);
  sim.report_interval_s = 0.05;
  const std::vector<std::string> cols = {"chassis.yaw_rate_rad_s", "chassis.roll_rad", "front_steer.angle_rad"};
  Recorder ra(a, cols), rb(b, cols);
  simulate(a, sa, sim, &ra);
  simulate(b, sb, sim, &rb);
  ASSERT_EQ(ra.size(), rb.size());
  for (const auto& n : cols) {
    double scale = 0, err = 0;
    for (std::size_t i = 0; i < ra.size(); ++i) {
      scale = std::max(scale, std::abs(ra.column(n)[i]));
      err = std::max(err, std::abs(ra.column(n)[i] - rb.column(n)[i]));
    }
    EXPECT_GT(scale, 1e-3) << n;
    EXPECT_LT(err / scale, 1e-6) << n;
  }
}
}  // namespace

TEST(ReducedCorner, ModelSizeAndDegreesOfFreedom) {
  const WheeledVehicle car(params("reduced"));
  const SimTK::State s = car.makeInitialState();
  // chassis 6 + 4 x (lower arm 1 + knuckle 2 + upper arm 1 + spin 1) = 26
  // mobilities; 2 arm rows per corner; the same 18 degrees of freedom.
  EXPECT_EQ(s.getNU(), 26);
  EXPECT_EQ(s.getNUDotErr(), 8);
  EXPECT_EQ(car.degreesOfFreedom(s), 18);
  EXPECT_DOUBLE_EQ(car.totalMass(), 924.0);
  EXPECT_THROW(car.corner(RF), Error);
}

TEST(ReducedCorner, UnknownSuspensionTemplateIsNamed) {
  WheeledVehicleParams p = params("constrained");
  p.setSuspensionTemplate("rigid");
  const std::string e = vdyn::test::errorOf([&] { WheeledVehicle car(p); });
  EXPECT_NE(e.find("appendix_a.json: axles.front.suspension: template: unknown suspension template 'rigid'"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("double_wishbone_reduced"), std::string::npos) << e;  // the known ones listed
}

TEST(ReducedCorner, LoopClosureAndSteeringAngleExactByConstruction) {
  const WheeledVehicle car(params("reduced"));
  SimTK::State s = car.makeInitialState();
  for (int c = 0; c < 4; ++c) {
    const DoubleWishboneParams& p = car.cornerParams(c);
    const ReducedWishboneCorner& rc = car.reducedCorner(c);
    for (double sq : {-0.15, 0.0, 0.1})
      for (double delta : {-0.3, 0.0, 0.07, 0.4}) {
        setReducedCornerPosition(s, rc, sq, delta);
        car.getScene().getSystem().realize(s, SimTK::Stage::Position);
        // Joint 2 (lower ball) and the cut joint 3 (upper ball) of the
        // constrained model, both on the arms' own Pins.
        const SimTK::Vec3 lowerGap = rc.lower_arm.findStationLocationInGround(s, p.lower_ball.parent_point_m) -
                                     rc.knuckle.findStationLocationInGround(s, p.lower_ball.child_point_m);
        const SimTK::Vec3 upperGap = rc.upper_arm.findStationLocationInGround(s, p.upper_ball.parent_point_m) -
                                     rc.knuckle.findStationLocationInGround(s, p.upper_ball.child_point_m);
        EXPECT_LT(lowerGap.norm(), 1e-14) << car.cornerName(c) << " s " << sq << " delta " << delta;
        EXPECT_LT(upperGap.norm(), 1e-14) << car.cornerName(c) << " s " << sq << " delta " << delta;
        // (A.1): the steering angle equals the coordinate.
        EXPECT_NEAR(steeringAngle(s, car.chassis(), rc.knuckle, SimTK::UnitVec3(p.wheel_spin_axis)), delta, 1e-14);
        EXPECT_LT(positionConstraintError(s), 1e-14);  // the arm rows
      }
  }
}

TEST(ReducedCorner, MobilizerDerivativesMatchFiniteDifferences) {
  const WheeledVehicleParams p = params("reduced");
  const WheeledVehicle car(p);
  for (const DoubleWishboneParams& cp : {car.cornerParams(RF), car.cornerParams(LR)}) {
    const WishboneLoop loop(cp);
    SimTK::MultibodySystem sys;
    SimTK::SimbodyMatterSubsystem matter(sys);
    ReducedKnuckleMobilizer m(matter, loop);
    const double h = 1e-5;
    for (double q0 : {-0.1, 0.05})
      for (double q1 : {-0.2, 0.3}) {
        const auto K = m.calcKinematics(q0, q1);
        for (int j = 0; j < 2; ++j) {
          const double e0 = j == 0 ? h : 0, e1 = j == 1 ? h : 0;
          const auto Kp = m.calcKinematics(q0 + e0, q1 + e1);
          const auto Km = m.calcKinematics(q0 - e0, q1 - e1);
          const SimTK::Mat33 dR = (Kp.X.R().asMat33() - Km.X.R().asMat33()) / (2 * h);
          const SimTK::Mat33 W = dR * K.X.R().asMat33().transpose();
          const SimTK::Vec3 dp = (Kp.X.p() - Km.X.p()) / (2 * h);
          for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(K.H[j][0][i], vee(W, i), 1e-8) << "w column " << j;
            EXPECT_NEAR(K.H[j][1][i], dp[i], 1e-9) << "v column " << j;
          }
          // dH[k][j] = d H_k / d q_j against a difference of H.
          for (int k = 0; k < 2; ++k)
            for (int a = 0; a < 2; ++a)
              for (int i = 0; i < 3; ++i)
                EXPECT_NEAR(K.dH[k][j][a][i], (Kp.H[k][a][i] - Km.H[k][a][i]) / (2 * h), 1e-7)
                    << "dH[" << k << "][" << j << "]";
        }
        // The upper arm angle and its derivatives.
        const SimTK::Vec3 f = loop.calcUpperArmAngle(q0), fp = loop.calcUpperArmAngle(q0 + h),
                          fm = loop.calcUpperArmAngle(q0 - h);
        EXPECT_NEAR(f[1], (fp[0] - fm[0]) / (2 * h), 1e-8);
        EXPECT_NEAR(f[2], (fp[1] - fm[1]) / (2 * h), 1e-7);
      }
  }
}

TEST(ReducedCorner, VelocitiesAndAccelerationsMatchFiniteDifferencesOfPositions) {
  // Simbody's own body velocities and bias accelerations of the knuckle (from
  // H and HDot) against differences of its positions along a motion.
  const WheeledVehicle car(params("reduced"));
  const SimTK::MultibodySystem& sys = car.getScene().getSystem();
  const ReducedWishboneCorner& rc = car.reducedCorner(LF);
  SimTK::State s = car.makeInitialState();
  const double q0 = 0.03, q1 = 0.2, u0 = 0.7, u1 = -1.3;
  // The motion q(t) = q + u t (constant rates) at time t.
  auto setMotion = [&](SimTK::State& x, double t) {
    setReducedCornerPosition(x, rc, q0 + u0 * t, q1 + u1 * t);
    rc.knuckle.setOneU(x, 0, u0);
    rc.knuckle.setOneU(x, 1, u1);
    rc.lower_arm.setOneU(x, 0, u0);
  };
  auto at = [&](double t) {  // knuckle pose in ground
    SimTK::State x = s;
    setMotion(x, t);
    sys.realize(x, SimTK::Stage::Position);
    return rc.knuckle.getBodyTransform(x);
  };
  setMotion(s, 0);
  sys.realize(s, SimTK::Stage::Velocity);
  const double h = 1e-4;
  const SimTK::Transform Xp = at(h), Xm = at(-h), X0 = at(0);
  const SimTK::Vec3 v = (Xp.p() - Xm.p()) / (2 * h), a = (Xp.p() - 2 * X0.p() + Xm.p()) / (h * h);
  const SimTK::Mat33 W = (Xp.R().asMat33() - Xm.R().asMat33()) / (2 * h) * X0.R().asMat33().transpose();
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(rc.knuckle.getBodyOriginVelocity(s)[i], v[i], 1e-8);
    EXPECT_NEAR(rc.knuckle.getBodyAngularVelocity(s)[i], vee(W, i), 1e-8);
  }
  // With udot = 0 the knuckle's acceleration is the bias HDot u (plus nothing
  // from the chassis, at rest): compare with the second difference.
  const SimTK::Vector udot(s.getNU(), 0.0);
  SimTK::Vector_<SimTK::SpatialVec> A;
  car.getScene().getMatter().calcBodyAccelerationFromUDot(s, udot, A);
  const SimTK::SpatialVec Ak = A[rc.knuckle.getMobilizedBodyIndex()];
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(Ak[1][i], a[i], 1e-5);
  // Angular: dw/dt from a difference of the angular velocities at t +- h.
  auto omega = [&](double t) {
    SimTK::State x = s;
    setMotion(x, t);
    sys.realize(x, SimTK::Stage::Velocity);
    return rc.knuckle.getBodyAngularVelocity(x);
  };
  const SimTK::Vec3 wdot = (omega(h) - omega(-h)) / (2 * h);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(Ak[0][i], wdot[i], 1e-6);
}

TEST(ReducedCorner, SameCh3SteadyStateAsTheConstrainedModel) {
  SteadyStateResult r[2];
  std::unique_ptr<WheeledVehicle> cars[2];
  for (int m = 0; m < 2; ++m) {
    cars[m] = ch3Car(kModels[m], "appendix_a_relaxation.json", true);
    const Scene& sc = cars[m]->getScene();
    SteadyStateSolver solver(sc, makeSteadyTurningProblem(sc, "chassis", {"rf.wheel", "lf.wheel", "rr.wheel", "lr.wheel"}, 0.0));
    r[m] = solver.solve(cars[m]->makeInitialState(10.0));
  }
  for (const char* out : {"chassis.yaw_rate_rad_s", "chassis.z_m", "chassis.roll_rad", "chassis.pitch_rad",
                          "chassis.side_slip_rad", "rf.spin_rad_s", "lf.spin_rad_s", "rr.spin_rad_s", "lr.spin_rad_s",
                          "front_steer.angle_rad", "rear_steer.angle_rad"}) {
    const double a = cars[0]->getScene().evalOutput(out, r[0].state);
    const double b = cars[1]->getScene().evalOutput(out, r[1].state);
    EXPECT_NEAR(b, a, 1e-8 * std::max(std::abs(a), 1e-2)) << out;
  }
  // The hold force is a multiplier, solved to the force tolerance.
  EXPECT_NEAR(cars[1]->getScene().evalOutput("speed_hold.force_N", r[1].state),
              cars[0]->getScene().evalOutput("speed_hold.force_N", r[0].state), 1e-5);
  for (int c = 0; c < 4; ++c)
    EXPECT_NEAR(cars[1]->suspensionAngle(r[1].state, c), cars[0]->suspensionAngle(r[0].state, c), 1e-9) << cars[0]->cornerName(c);
}

TEST(ReducedCorner, SameCh3TransientAsTheConstrainedModel) {
  const auto con = ch3Car("constrained", "appendix_a_relaxation.json", false);
  const auto red = ch3Car("reduced", "appendix_a_relaxation.json", false);
  SimTK::State sc = con->makeInitialState(10.0);
  SimTK::State sr = red->makeInitialState(10.0);
  // Both start in the constrained model's assembled configuration.
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(red->suspensionAngle(sr, c), con->suspensionAngle(sc, c), 1e-12) << con->cornerName(c);
  const SimTK::State mapped = red->makeStateLike(*con, sc);
  EXPECT_LT((mapped.getQ() - sr.getQ()).normInf(), 1e-12);
  expectSameCh3Transient(con->getScene(), sc, red->getScene(), sr);
}

TEST(ReducedCorner, MixedSensitivityAgreesWithTheConstrainedModel) {
  // d psi / d (front spring stiffness), psi = int roll rate^2 over the first
  // second of the chapter 3 manoeuvre (ch4_sensitivity --vehicle fourws), by
  // the mixed method on each model.
  SensitivityResult r[2];
  for (int m = 0; m < 2; ++m) {
    SensitivityProblem p;
    p.model = SceneDesign::fromAnalysis(SceneDescription::fromFile(
        "scenes/ch4_sensitivity_fourws.json", standardRegistry(),
        {{"vehicle.data", "appendix_a_relaxation.json"}, {"vehicle.overrides.formulation", kModels[m]}}));
    p.parameters = {"front.spring.stiffness_N_per_m"};
    p.cost = CostFunctional::parse("integral_of_square:chassis.roll_rate_rad_s");
    p.t_end_s = 1.0;
    p.integrator.accuracy = 1e-8;
    SensitivitySettings set;
    set.tolerance = 1e-4;
    r[m] = makeSensitivityMethod("mixed", set)->compute(p);
  }
  EXPECT_GT(std::abs(r[0].dpsi_db[0]), 0.0);
  EXPECT_NEAR(r[1].psi / r[0].psi, 1.0, 1e-6);
  EXPECT_NEAR(r[1].dpsi_db[0] / r[0].dpsi_db[0], 1.0, 1e-3);
}

// Dense forward dynamics (reduced_dense.h): the same accelerations as
// Simbody's rows in the same state, the same transient, rows held.
TEST(ReducedDense, SameAccelerationsAsSimbodysRowsInTheSameState) {
  const auto red = ch3Car("reduced", "appendix_a_relaxation.json", false);
  const SimTK::MultibodySystem& sys = red->getScene().getSystem();
  SimTK::State s = red->makeInitialState(10.0);
  // To 1 s, mid steering step: turning, rolling, steering rates non-zero.
  simulate(red->getScene(), s, ch3Simulation(1.0), nullptr);
  sys.project(s, 1e-14);  // on the constraint manifold: the Baumgarte terms vanish
  SimTK::State d = s;
  red->useDenseRows(d);
  sys.realize(s, SimTK::Stage::Acceleration);
  sys.realize(d, SimTK::Stage::Acceleration);
  EXPECT_EQ(d.getNUDotErr(), 0);  // Simbody solves no row in the dense state
  EXPECT_EQ(red->degreesOfFreedom(d), red->degreesOfFreedom(s));
  const auto [perr, verr] = red->denseRows()->calcRowErrors(d);
  EXPECT_LT(perr, 1e-12);
  EXPECT_LT(verr, 1e-10);
  const double scale = s.getUDot().normInf();
  EXPECT_GT(scale, 1.0);
  EXPECT_LT((d.getUDot() - s.getUDot()).normInf() / scale, 1e-8) << d.getUDot() << "\n" << s.getUDot();
  const auto& hold = dynamic_cast<const SpeedHoldPlugin&>(*red->getScene().getPlugins().back());
  EXPECT_NEAR(hold.calcForce(d), hold.calcForce(s), 1e-8 * std::abs(hold.calcForce(s)) + 1e-9);
}

/// A random state of the reduced ch3 car (steering rates and accelerations
/// non-zero, arms, spins, chassis motion perturbed) projected onto Simbody's
/// rows (1e-13): on the manifold, where the dense rows' Baumgarte terms vanish.
SimTK::State randomStateOnTheRows(const WheeledVehicle& red, unsigned seed) {
  const SimTK::MultibodySystem& sys = red.getScene().getSystem();
  SimTK::State s = red.makeInitialState(10.0);
  s.setTime(0.9);  // mid steering step
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < s.getNQ(); ++i) s.updQ()[i] += 0.01 * unit(gen);
  for (int i = 0; i < s.getNU(); ++i) s.updU()[i] += 0.3 * unit(gen);
  sys.realize(s, SimTK::Stage::Position);
  sys.project(s, 1e-10);
  sys.project(s, 1e-13);  // from 1e-1 in one go Simbody stops at 7e-14
  return s;
}

TEST(ReducedDense, RowMatrixOfTheArticulatedBlocksEqualsOneMInvProductPerRow) {
  // G M^-1 G^T two ways: from the articulated-body inertias (what the
  // evaluation uses) and from one multiplyByMInv per row (independent).
  const auto red = ch3Car("reduced", "appendix_a_relaxation.json", false);
  const SimTK::MultibodySystem& sys = red->getScene().getSystem();
  for (unsigned seed : {1u, 2u, 3u}) {
    SimTK::State d = randomStateOnTheRows(*red, seed);
    red->useDenseRows(d);
    sys.realize(d, SimTK::Stage::Dynamics);
    const SimTK::Matrix blocks = red->denseRows()->calcRowMatrix(d, false);
    const SimTK::Matrix products = red->denseRows()->calcRowMatrix(d, true);
    ASSERT_EQ(blocks.nrow(), red->denseRows()->numRows());
    double scale = 0, diff = 0;
    for (int i = 0; i < products.nrow(); ++i)
      for (int j = 0; j < products.ncol(); ++j) {
        scale = std::max(scale, std::abs(products(i, j)));
        diff = std::max(diff, std::abs(blocks(i, j) - products(i, j)));
      }
    EXPECT_GT(scale, 0.0);
    EXPECT_LT(diff / scale, 1e-12) << blocks << "\n" << products;
  }
}

TEST(ReducedDense, SameAccelerationsAsSimbodysRowsInRandomStatesOnTheManifold) {
  const auto red = ch3Car("reduced", "appendix_a_relaxation.json", false);
  const SimTK::MultibodySystem& sys = red->getScene().getSystem();
  for (unsigned seed : {4u, 5u, 6u}) {
    SimTK::State s = randomStateOnTheRows(*red, seed);
    SimTK::State d = s;
    red->useDenseRows(d);
    sys.realize(s, SimTK::Stage::Acceleration);
    sys.realize(d, SimTK::Stage::Acceleration);
    ASSERT_GT(s.getNUDotErr(), 0);  // Simbody's constraint solve ...
    ASSERT_EQ(d.getNUDotErr(), 0);  // ... against the dense one
    const auto [perr, verr] = red->denseRows()->calcRowErrors(d);
    EXPECT_LT(perr, 1e-12);
    EXPECT_LT(verr, 1e-11);
    const double scale = s.getUDot().normInf();
    EXPECT_GT(scale, 1.0);
    EXPECT_LT((d.getUDot() - s.getUDot()).normInf() / scale, 1e-10) << d.getUDot() << "\n" << s.getUDot();
  }
}

TEST(ReducedDense, SameCh3TransientAsSimbodysRows) {
  const auto red = ch3Car("reduced", "appendix_a_relaxation.json", false);
  SimTK::State sr = red->makeInitialState(10.0);
  SimTK::State sd = sr;
  red->useDenseRows(sd);
  ASSERT_NO_FATAL_FAILURE(expectSameCh3Transient(red->getScene(), sr, red->getScene(), sd));
  red->getScene().getSystem().realize(sd, SimTK::Stage::Velocity);
  const auto [perr, verr] = red->denseRows()->calcRowErrors(sd);
  EXPECT_LT(perr, 1e-9);  // drift held by the Baumgarte terms
  EXPECT_LT(verr, 1e-8);
}

TEST(ReducedDense, NeedsReducedTemplatesAndRowsItSolves) {
  // "dense" (or "reduced") asked of an axle without a reduced form: named Error.
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a_solid_rear.json");
  p.formulation = "dense";
  EXPECT_EQ(vdyn::test::errorOf([&] { WheeledVehicle car(p); }),
            "vehicle formulation \"dense\": axle 'rear''s template solid_axle has no reduced form (formulation "
            "\"constrained\" or \"auto\" runs it)");
  // auto: constrained, and says why.
  p.formulation = "auto";
  const WheeledVehicle solid(p);
  EXPECT_EQ(solid.getFormulation().name, "constrained");
  EXPECT_EQ(solid.getFormulation().why, "axle 'rear''s template solid_axle has no reduced form");
  // The constrained model has no dense rows.
  const auto con = ch3Car("constrained", "appendix_a.json", true);
  EXPECT_EQ(con->getFormulation().name, "constrained");
  EXPECT_EQ(con->getFormulation().why, "asked (formulation \"constrained\")");
  SimTK::State s = con->makeInitialState(10.0);
  EXPECT_THROW(con->useDenseRows(s), Error);
  // auto on App. A: the reduced templates, dense rows.
  const auto au = ch3Car("auto", "appendix_a.json", true);
  EXPECT_TRUE(au->isReduced());
  EXPECT_EQ(au->getFormulation().name, "dense");
  EXPECT_EQ(au->getFormulation().why, "every axle's template supports it");
  EXPECT_TRUE(au->denseRows()->isActive(au->makeInitialState(10.0)));
  // A constraint the dense rows do not solve (a body lock): auto stays on
  // Simbody's rows, reduced, and names it; "dense" is an Error naming it.
  auto locked = ch3Car("auto", "appendix_a.json", true);
  SimTK::MobilizedBody chassis = locked->chassis();  // a handle
  SimTK::Constraint::Weld(locked->updScene().updMatter().Ground(), chassis);
  EXPECT_EQ(locked->getFormulation().name, "reduced");
  EXPECT_NE(locked->getFormulation().why.find("constraint the dense system does not solve"), std::string::npos)
      << locked->getFormulation().why;
}
