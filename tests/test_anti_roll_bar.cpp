// The anti-roll bar template "torsion_bar" (vehicles/templates/torsion_bar/)
// on App. A with a front bar (vehicles/data/appendix_a_arb.json), on the
// reduced double wishbone (q = [s, delta] per corner, so a corner is moved
// along its loop by setting s): no force in heave; its energy against
// 1/2 k_t phi^2 from the attachment points and its generalized force against
// -dV/dq by finite differences; its work over a transient against -delta V;
// and its effect on the roll gradient under a roll moment against the closed
// form of torsion_bar.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "vdyn/steady_state/steady_state.h"
#include "vdyn/steering/steering.h"
#include "vdyn/templates/torsion_bar.h"
#include "vdyn/vehicles/reduced_wishbone.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {

WheeledVehicleParams arbParams(bool bar = true, bool reduced = true) {
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a_arb.json");
  p.formulation = reduced ? "reduced" : "constrained";
  if (!bar) p.updAxle("front").anti_roll_bar = Json::object();
  return p;
}

const TorsionBarParams& barOf(const WheeledVehicle& car) {
  return dynamic_cast<const TorsionBar&>(*car.antiRollBar(car.axleIndex("front"))).params();
}

/// The bar's generalized force alone (mobility space), N or N m.
SimTK::Vector barForce(const WheeledVehicle& car, const SimTK::State& s) {
  const Scene& sc = car.getScene();
  sc.getSystem().realize(s, SimTK::Stage::Velocity);
  SimTK::Vector_<SimTK::SpatialVec> bf(sc.getMatter().getNumBodies());
  bf.setToZero();
  SimTK::Vector_<SimTK::Vec3> pf(sc.getMatter().getNumParticles());
  pf.setToZero();
  SimTK::Vector mf(s.getNU());
  mf.setToZero();
  for (SimTK::ForceIndex fx : car.antiRollBar(0)->getForceIndices())
    sc.getForces().getForce(fx).calcForceContribution(s, bf, pf, mf);
  SimTK::Vector f;
  sc.getMatter().multiplyBySystemJacobianTranspose(s, bf, f);
  return f + mf;
}

double barEnergy(const WheeledVehicle& car, const SimTK::State& s) {
  car.getScene().getSystem().realize(s, SimTK::Stage::Position);
  double v = 0;
  for (SimTK::ForceIndex fx : car.antiRollBar(0)->getForceIndices())
    v += car.getScene().getForces().getForce(fx).calcPotentialEnergyContribution(s);
  return v;
}

/// The attachment point of `side` of the front axle in the chassis frame, z (m).
double attachZ(const WheeledVehicle& car, const SimTK::State& s, int side) {
  const SimTK::Vec3 p = barOf(car).attach_point_m;
  const SimTK::Vec3 ps = side == 0 ? p : SimTK::Vec3(p[0], -p[1], p[2]);
  const SimTK::MobilizedBody& arm = car.reducedCorner(side).lower_arm;
  car.getScene().getSystem().realize(s, SimTK::Stage::Position);
  return car.chassis().findStationAtGroundPoint(s, arm.findStationLocationInGround(s, ps))[2];
}

/// dz of the attachment point from its position in the scene's default state
/// (every q = 0: the tabulated configuration), computed apart from the bar.
double attachDz(const WheeledVehicle& car, const SimTK::State& s, int side) {
  return attachZ(car, s, side) - attachZ(car, car.getScene().getDefaultState(), side);
}

/// The (A.1)-style angle coordinate of a reduced knuckle (q[1]).
double deltaOf(const ReducedWishboneCorner& rc, const SimTK::State& s) { return rc.knuckle.getOneQ(s, 1); }

void moveCorner(const WheeledVehicle& car, SimTK::State& s, int c, double ds) {
  const ReducedWishboneCorner& rc = car.reducedCorner(c);
  setReducedCornerPosition(s, rc, rc.lower_arm.getOneQ(s, 0) + ds, deltaOf(rc, s));
}

}  // namespace

TEST(AntiRollBar, ListedAndRegistered) {
  const WheeledVehicle car(arbParams());
  ASSERT_NE(car.antiRollBar(0), nullptr);
  EXPECT_EQ(car.antiRollBar(1), nullptr);  // the rear axle has none
  EXPECT_EQ(car.antiRollBar(0)->templateName(), "torsion_bar");
  EXPECT_EQ(barOf(car).stiffness_N_m_per_rad, 1500.0);
  EXPECT_TRUE(car.getScene().hasOutput("front_arb.twist_rad"));
  EXPECT_TRUE(car.getScene().hasOutput("front_arb.torque_N_m"));
  EXPECT_FALSE(car.getScene().hasOutput("rear_arb.twist_rad"));
  EXPECT_EQ(vehiclePlugins().knownChoices(kAntiRollBarFamily), (std::vector<std::string>{"torsion_bar"}));
}

TEST(AntiRollBar, WrongRoleAndBadKeysAreNamedErrors) {
  auto errorOf = [](const Json& bar) -> std::string {
    Json j = ParamReader::fromFile("appendix_a_arb.json").json();
    j["axles"]["front"]["anti_roll_bar"] = bar;
    try {
      const WheeledVehicle car(WheeledVehicleParams::fromParams(ParamReader::fromJson(j, "arb.json")));
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  Json bar = ParamReader::fromFile("appendix_a_arb.json").json()["axles"]["front"]["anti_roll_bar"];
  Json wrong = bar;
  wrong["role"] = "strut";
  const std::string e = errorOf(wrong);
  EXPECT_NE(e.find("axles.front.anti_roll_bar"), std::string::npos) << e;
  EXPECT_NE(e.find("axle 'front'"), std::string::npos) << e;
  EXPECT_NE(e.find("'torsion_bar'"), std::string::npos) << e;
  EXPECT_NE(e.find("role 'strut'"), std::string::npos) << e;
  EXPECT_NE(e.find("double_wishbone"), std::string::npos) << e;
  EXPECT_NE(e.find("roles: lower_arm, knuckle, upper_arm, wheel"), std::string::npos) << e;
  Json unknown = bar;
  unknown["template"] = "blade";
  const std::string u = errorOf(unknown);
  EXPECT_NE(u.find("axles.front.anti_roll_bar"), std::string::npos) << u;
  EXPECT_NE(u.find("'blade'"), std::string::npos) << u;
  EXPECT_NE(u.find("torsion_bar"), std::string::npos) << u;
  Json negative = bar;
  negative["lever_m"] = -0.2;
  EXPECT_NE(errorOf(negative).find("lever_m"), std::string::npos) << errorOf(negative);
  Json extra = bar;
  extra["zz_not_a_key"] = 1;
  EXPECT_NE(errorOf(extra).find("zz_not_a_key"), std::string::npos) << errorOf(extra);
}

TEST(AntiRollBar, NoForceInHeave) {
  const WheeledVehicle car(arbParams());
  SimTK::State s = car.makeInitialState();
  const double k = barOf(car).stiffness_N_m_per_rad;
  for (double ds : {0.0, 0.03, -0.05}) {
    SimTK::State h = s;
    moveCorner(car, h, RF, ds);
    moveCorner(car, h, LF, ds);
    EXPECT_NEAR(attachDz(car, h, 0), attachDz(car, h, 1), 1e-12) << ds;  // the mirror moves alike
    EXPECT_NEAR(car.getScene().evalOutput("front_arb.twist_rad", h), 0.0, 1e-12) << ds;
    EXPECT_LT(barForce(car, h).normInf(), 1e-9 * k) << ds;
    EXPECT_LT(barEnergy(car, h), 1e-20 * k) << ds;
  }
}

TEST(AntiRollBar, EnergyIsHalfKPhiSquaredAndTheForceItsGradient) {
  const WheeledVehicle car(arbParams());
  const TorsionBarParams& bp = barOf(car);
  const double k = bp.stiffness_N_m_per_rad, L = bp.lever_m;
  SimTK::State s = car.makeInitialState();
  moveCorner(car, s, RF, 0.03);
  moveCorner(car, s, LF, -0.02);
  const double dzR = attachDz(car, s, 0), dzL = attachDz(car, s, 1);
  const double phi = std::asin(dzR / L) - std::asin(dzL / L);
  EXPECT_GT(std::abs(phi), 0.02);
  EXPECT_NEAR(car.getScene().evalOutput("front_arb.twist_rad", s), phi, 1e-12);
  EXPECT_NEAR(car.getScene().evalOutput("front_arb.torque_N_m", s), k * phi, 1e-9 * k);
  EXPECT_NEAR(barEnergy(car, s), 0.5 * k * phi * phi, 1e-12 * k);
  // Generalized force along each corner's loop against -dV/ds (central differences).
  const SimTK::Vector f = barForce(car, s);
  for (int c : {RF, LF}) {
    const double eps = 1e-5;
    SimTK::State sp = s, sm = s;
    moveCorner(car, sp, c, eps);
    moveCorner(car, sm, c, -eps);
    const SimTK::Vector dq = (sp.getQ() - sm.getQ()) / (2 * eps);
    SimTK::Vector du;  // the same motion as generalized speeds (qdot = N u)
    car.getScene().getMatter().multiplyByNInv(s, false, dq, du);
    const double work = ~f * du;
    const double dVds = (barEnergy(car, sp) - barEnergy(car, sm)) / (2 * eps);
    std::printf("corner %d: f . dq/ds = %.9g N m, -dV/ds = %.9g N m\n", c, work, -dVds);
    EXPECT_NEAR(work, -dVds, 1e-6 * std::abs(dVds)) << c;
  }
}

TEST(AntiRollBar, WorkOverAnUndampedTransientIsMinusDeltaV) {
  const WheeledVehicle car(arbParams());
  const SimTK::MultibodySystem& sys = car.getScene().getSystem();
  SimTK::State s = car.makeInitialState();
  moveCorner(car, s, RF, 0.04);  // the right front wheel lifted: the car rocks
  sys.realize(s, SimTK::Stage::Velocity);
  SimTK::RungeKuttaMersonIntegrator integ(sys);
  integ.setAccuracy(1e-10);
  SimTK::TimeStepper ts(sys, integ);
  ts.initialize(s);
  const int n = 1000;  // Simpson over 0.1 s in 0.1 ms intervals
  const double h = 1e-4;
  auto power = [&](const SimTK::State& st) { return ~barForce(car, st) * st.getU(); };
  const double v0 = barEnergy(car, ts.getState());
  double work = power(ts.getState());
  for (int i = 1; i <= n; ++i) {
    ts.stepTo(i * h);
    work += (i == n ? 1 : (i % 2 ? 4 : 2)) * power(ts.getState());
  }
  work *= h / 3;
  const double v1 = barEnergy(car, ts.getState());
  std::printf("bar: V(0) = %.9g J, V(0.1 s) = %.9g J, work = %.9g J\n", v0, v1, work);
  EXPECT_GT(std::abs(v1 - v0), 0.1 * v0);  // the transient moves the bar
  EXPECT_NEAR(work, -(v1 - v0), 1e-5 * std::max(v0, v1));
}

TEST(AntiRollBar, DampingTorqueIsCTimesTheTwistRateAndDissipates) {
  WheeledVehicleParams p = arbParams();
  p.updAxle("front").anti_roll_bar["damping_N_m_s_per_rad"] = 40.0;
  const WheeledVehicle car(p);
  const SimTK::MultibodySystem& sys = car.getScene().getSystem();
  SimTK::State s = car.makeInitialState();
  moveCorner(car, s, RF, 0.04);
  SimTK::RungeKuttaMersonIntegrator integ(sys);
  integ.setAccuracy(1e-8);
  SimTK::TimeStepper ts(sys, integ);
  ts.initialize(s);
  ts.stepTo(0.01);  // moving now
  const SimTK::State& st = ts.getState();
  sys.realize(st, SimTK::Stage::Velocity);
  // phi_dot by central differences of the twist along qdot.
  const double eps = 1e-7;
  SimTK::State sp = st, sm = st;
  sp.updQ() += eps * st.getQDot();
  sm.updQ() -= eps * st.getQDot();
  const Scene& sc = car.getScene();
  const double phi = sc.evalOutput("front_arb.twist_rad", st);
  const double phidot = (sc.evalOutput("front_arb.twist_rad", sp) - sc.evalOutput("front_arb.twist_rad", sm)) / (2 * eps);
  const double T = 1500.0 * phi + 40.0 * phidot;
  EXPECT_GT(std::abs(40.0 * phidot), 0.1 * std::abs(1500.0 * phi));  // the damping term matters here
  EXPECT_NEAR(sc.evalOutput("front_arb.torque_N_m", st), T, 1e-6 * std::abs(T));
  const double power = ~barForce(car, st) * st.getU();
  EXPECT_NEAR(power, -T * phidot, 1e-6 * std::abs(T * phidot));  // dV/dt plus the dissipation c phi_dot^2
}

namespace {

/// App. A (with or without its front bar), the knuckles held at zero steer,
/// a roll moment M about ground x on the chassis.
std::unique_ptr<WheeledVehicle> makeRollCar(bool bar, bool reduced, double moment_N_m) {
  auto car = std::make_unique<WheeledVehicle>(arbParams(bar, reduced));
  car->addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.0));
  car->addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.0));
  SimTK::Force::ConstantTorque(car->updScene().updForces(), car->chassis(), SimTK::Vec3(moment_N_m, 0, 0));
  return car;
}

struct RollRun {
  std::unique_ptr<WheeledVehicle> car;
  double roll_rad = 0;
  SimTK::State state;
};

/// Static equilibrium under the roll moment (makeRestProblem: speeds held at
/// zero, chassis x, y, yaw and the spins ineffective), on the
/// constrained double wishbone (the steady-state solver's model of the
/// vehicle report).
RollRun rollUnder(bool bar, double moment_N_m) {
  RollRun r;
  r.car = makeRollCar(bar, false, moment_N_m);
  const Scene& sc = r.car->getScene();
  std::vector<std::string> wheels;
  for (int c = 0; c < r.car->numCorners(); ++c) wheels.push_back(r.car->cornerName(c) + ".wheel");
  SteadyStateSolver solver(sc, makeRestProblem(sc, "chassis", wheels, 0));
  r.state = solver.solve(r.car->makeInitialState(0.0)).state;
  sc.getSystem().realize(r.state, SimTK::Stage::Position);
  const SimTK::Rotation R = r.car->chassis().getBodyRotation(r.state);
  r.roll_rad = std::atan2(R[2][1], R[2][2]);
  return r;
}

/// One corner's wheel rate and the bar's motion ratio about the state s, by
/// central differences along the loop: w the wheel centre along z_C relative
/// to the chassis; the spring's V(w) (its preload's geometric term included).
struct CornerRates {
  double wheel_rate_N_per_m = 0, bar_motion_ratio = 0, half_track_m = 0, attach_dz_m = 0;
};
CornerRates cornerRates(const WheeledVehicle& car, const SimTK::State& s, int c) {
  const ReducedWishboneCorner& rc = car.reducedCorner(c);
  const double s0 = rc.lower_arm.getOneQ(s, 0), d0 = deltaOf(rc, s), e = 1e-4;
  double w[3], V[3], z[3];
  for (int i = 0; i < 3; ++i) {
    SimTK::State t = s;
    setReducedCornerPosition(t, rc, s0 + (i - 1) * e, d0);
    car.getScene().getSystem().realize(t, SimTK::Stage::Position);
    w[i] = car.chassis().findStationAtGroundPoint(t, rc.wheel.getBodyOriginLocation(t))[2];
    V[i] = rc.spring.calcPotentialEnergyContribution(t);
    z[i] = c / 2 == 0 ? attachZ(car, t, c % 2) : 0;
  }
  const double ws = (w[2] - w[0]) / (2 * e), wss = (w[2] - 2 * w[1] + w[0]) / (e * e);
  const double Vs = (V[2] - V[0]) / (2 * e), Vss = (V[2] - 2 * V[1] + V[0]) / (e * e);
  CornerRates r;
  r.wheel_rate_N_per_m = (Vss - Vs / ws * wss) / (ws * ws);
  r.bar_motion_ratio = (z[2] - z[0]) / (2 * e) / ws;
  car.getScene().getSystem().realize(s, SimTK::Stage::Position);
  r.half_track_m = std::abs(car.chassis().findStationAtGroundPoint(s, rc.wheel.getBodyOriginLocation(s))[1]);
  if (c / 2 == 0) r.attach_dz_m = attachDz(car, s, c % 2);
  return r;
}

}  // namespace

TEST(AntiRollBar, RollGradientChangeMatchesTheClosedForm) {
  const double M = 300.0;  // N m about x: about 0.01 rad of roll
  const RollRun n0 = rollUnder(false, 0.0), np = rollUnder(false, M), nm = rollUnder(false, -M);
  const RollRun bp = rollUnder(true, M), bm = rollUnder(true, -M);
  EXPECT_NEAR(n0.roll_rad, 0.0, 1e-9);
  const double G0 = (np.roll_rad - nm.roll_rad) / (2 * M), G1 = (bp.roll_rad - bm.roll_rad) / (2 * M);  // rad/(N m)
  // Closed form (torsion_bar.h) from the model's rates about the unloaded equilibrium.
  // The reduced model of the same mechanism in the unloaded equilibrium, whose
  // corners move along their loops by s.
  const std::unique_ptr<WheeledVehicle> red = makeRollCar(true, true, 0.0);
  const WheeledVehicle& car = *red;
  const SimTK::State s0 = car.makeStateLike(*n0.car, n0.state);
  const TorsionBarParams& bar = barOf(car);
  const CornerRates f = cornerRates(car, s0, RF), r = cornerRates(car, s0, RR);
  const double kTire = car.tire(0).getModel().vertical().radial_stiffness_N_per_m;
  const double tf = 2 * f.half_track_m, tr = 2 * r.half_track_m;
  auto series = [](double a, double b) { return a * b / (a + b); };
  const double Ksf = f.wheel_rate_N_per_m * tf * tf / 2, Ksr = r.wheel_rate_N_per_m * tr * tr / 2;
  const double Ktf = kTire * tf * tf / 2, Ktr = kTire * tr * tr / 2;
  const double Lp = std::sqrt(bar.lever_m * bar.lever_m - f.attach_dz_m * f.attach_dz_m);
  const double Karb = bar.stiffness_N_m_per_rad * std::pow(f.bar_motion_ratio * tf / Lp, 2);
  const double dK = series(Ksf + Karb, Ktf) - series(Ksf, Ktf);
  const double K0m = 1 / G0, K1m = 1 / G1;
  const double G1cf = 1 / (K0m + dK);
  std::printf("front: wheel rate %.1f N/m, track %.4f m, bar motion ratio %.5f, dz0 %.5f m, L' %.5f m\n",
              f.wheel_rate_N_per_m, tf, f.bar_motion_ratio, f.attach_dz_m, Lp);
  std::printf("rear: wheel rate %.1f N/m, track %.4f m\n", r.wheel_rate_N_per_m, tr);
  std::printf("K_arb = %.1f N m/rad; front axle roll stiffness %.1f -> %.1f N m/rad (springs and tires in series)\n",
              Karb, series(Ksf, Ktf), series(Ksf + Karb, Ktf));
  std::printf("vehicle roll stiffness: measured %.1f (no bar), %.1f (bar); closed form springs+tires %.1f, +bar %.1f\n",
              K0m, K1m, series(Ksf, Ktf) + series(Ksr, Ktr), series(Ksf + Karb, Ktf) + series(Ksr, Ktr));
  std::printf("roll gradient: %.6e -> %.6e rad/(N m) measured; change %.6e measured, %.6e closed form (%.3f %%)\n", G0,
              G1, G1 - G0, G1cf - G0, 100 * ((G1 - G0) / (G1cf - G0) - 1));
  EXPECT_LT(G1, 0.8 * G0);  // the bar stiffens the car in roll
  EXPECT_NEAR((G1 - G0) / (G1cf - G0), 1.0, 0.02);
}
