// Design sensitivity (chapter 4): every method against a closed form, the mixed
// method against the reference on the quarter car, and the residual Jacobians
// of the mixed method against finite differences of Simbody's forward dynamics.
#include <cmath>
#include <complex>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vdyn/core/simulation.h"
#include "vdyn/sensitivity/mixed.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/vehicles/vehicle_designs.h"

using namespace vdyn;

namespace {

// A mass m on a vertical slider, tied to a road z_g = A sin(w t) by a spring k
// and a damper c (no gravity). Started on its periodic steady state, so over
// whole periods psi = int x''^2 dt = (T/2) w^4 |X|^2, |X|^2 = A^2 N / D with
// N = k^2 + c^2 w^2, D = (k - m w^2)^2 + c^2 w^2.
const double kA = 0.02, kW = 2 * SimTK::Pi * 2.0, kT = 1.0;  // m, rad/s, s (two periods)

class RoadSpringDamper : public SimTK::Force::Custom::Implementation {
 public:
  RoadSpringDamper(SimTK::MobilizedBody::Slider b, double k, double c) : b_(b), k_(k), c_(c) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>&, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector& mobilityForces) const override {
    const double t = s.getTime(), zg = kA * std::sin(kW * t), vg = kA * kW * std::cos(kW * t);
    b_.applyOneMobilityForce(s, 0, -k_ * (b_.getOneQ(s, 0) - zg) - c_ * (b_.getOneU(s, 0) - vg), mobilityForces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  SimTK::MobilizedBody::Slider b_;
  double k_, c_;
};

class OscillatorInstance : public DesignInstance {
 public:
  OscillatorInstance(double m, double k, double c, bool extraZ) : m_(m), k_(k), c_(c) {
    SimTK::Body::Rigid body(SimTK::MassProperties(m, SimTK::Vec3(0), SimTK::Inertia(1)));
    body_ = SimTK::MobilizedBody::Slider(sc_.updMatter().Ground(), body);
    SimTK::Force::Custom(sc_.updForces(), new RoadSpringDamper(body_, k, c));
    const auto b = body_;
    sc_.addOutput({"x_m", "m", SimTK::Stage::Position, [b](const SimTK::State& s) { return b.getOneQ(s, 0); }});
    sc_.addOutput({"a_m_s2", "m/s^2", SimTK::Stage::Acceleration,
                   [b](const SimTK::State& s) { return b.getOneUDot(s, 0); }});
    if (extraZ) sc_.addIntegralOfSquare("x_m");  // stands for a tire's auxiliary state
  }
  Scene& updScene() override { return sc_; }
  const Scene& getScene() const override { return sc_; }
  SimTK::State makeInitialState() const override {
    const std::complex<double> X =
        kA * std::complex<double>(k_, c_ * kW) / std::complex<double>(k_ - m_ * kW * kW, c_ * kW);
    SimTK::State s = sc_.getDefaultState();
    body_.setOneQ(s, 0, X.imag());        // x = Im(X e^{iwt})
    body_.setOneU(s, 0, kW * X.real());
    return s;
  }

 private:
  Scene sc_;
  SimTK::MobilizedBody::Slider body_;
  double m_, k_, c_;
};

class OscillatorDesign : public DesignModel {
 public:
  explicit OscillatorDesign(bool extraZ = false)
      : DesignModel({{"mass_kg", "m", "kg", 1.0, 1.0},
                     {"stiffness_N_per_m", "k", "N/m", 100.0, 100.0},
                     {"damping_N_s_per_m", "c", "N s/m", 4.0, 1.0}}),
        extraZ_(extraZ) {}
  std::string describe() const override { return "oscillator"; }

 protected:
  std::unique_ptr<DesignInstance> DoBuild(const std::vector<double>& b) const override {
    return std::make_unique<OscillatorInstance>(b[0], b[1], b[2], extraZ_);
  }

 private:
  bool extraZ_;
};

struct ClosedForm {
  double psi;
  double d[3];  // d psi / d (m, k, c)
};

ClosedForm closedForm(double m, double k, double c) {
  const double w2 = kW * kW, N = k * k + c * c * w2, E = k - m * w2, D = E * E + c * c * w2;
  const double f = 0.5 * kT * w2 * w2 * kA * kA;
  return {f * N / D,
          {f * 2 * w2 * N * E / (D * D), f * (2 * k * D - 2 * N * E) / (D * D),
           f * (2 * c * w2 * D - 2 * c * w2 * N) / (D * D)}};
}

SensitivityProblem oscillatorProblem(bool extraZ = false) {
  SensitivityProblem p;
  p.model = std::make_shared<OscillatorDesign>(extraZ);
  p.parameters = {"m", "k", "c"};
  p.cost = CostFunctional::parse("integral_of_square:a_m_s2");
  p.t_end_s = kT;
  p.integrator.accuracy = 1e-8;
  return p;
}

}  // namespace

TEST(Sensitivity, ClosedFormCheckOfTheOscillator) {
  // The closed form itself against a plain simulation.
  const SensitivityProblem p = oscillatorProblem();
  IntegratorSettings tight;
  tight.accuracy = 1e-10;
  const double psi = evaluateCost(p, {1.0, 100.0, 4.0}, tight);
  EXPECT_NEAR(psi / closedForm(1, 100, 4).psi, 1.0, 1e-7);
}

TEST(Sensitivity, EveryMethodMatchesTheClosedForm) {
  const SensitivityProblem p = oscillatorProblem();
  const ClosedForm cf = closedForm(1, 100, 4);
  // Stated errors: mixed its tolerance (plus the nominal's ~accuracy);
  // fd_forward about sqrt(accuracy); fd_central about accuracy^(2/3);
  // reference its two-size agreement.
  const std::vector<std::pair<std::string, double>> bounds = {
      {"mixed", 1e-5}, {"fd_forward", 1e-3}, {"fd_central", 1e-4}, {"reference", 1e-6}};
  for (const auto& [name, bound] : bounds) {
    SensitivitySettings set;
    set.tolerance = 1e-6;
    const SensitivityResult r = makeSensitivityMethod(name, set)->compute(p);
    ASSERT_EQ(r.dpsi_db.size(), 3u);
    EXPECT_NEAR(r.psi / cf.psi, 1.0, 1e-6) << name;
    for (int i = 0; i < 3; ++i) {
      const double rel = std::abs(r.dpsi_db[i] - cf.d[i]) / std::abs(cf.d[i]);
      std::printf("  %-10s d psi / d %s = %.10g (closed form %.10g), rel. error %.2e\n", name.c_str(),
                  p.parameters[i].c_str(), r.dpsi_db[i], cf.d[i], rel);
      EXPECT_LT(rel, bound) << name << " parameter " << p.parameters[i];
    }
  }
}

TEST(Sensitivity, MixedFinalValueAndMaximumCosts) {
  // Final value and maximum of x: mixed against central differences.
  // (The maximum's t* comes from a parabola through the grid maximum, so its
  // error is larger than the integral's.)
  for (const auto& [cost, tol] : std::vector<std::pair<std::string, double>>{{"final_value:x_m", 1e-4},
                                                                             {"maximum:x_m", 1e-2}}) {
    SensitivityProblem p = oscillatorProblem();
    p.cost = CostFunctional::parse(cost);
    SensitivitySettings set;
    set.tolerance = tol;
    // The maximum over time is only piecewise smooth in b (its time moves), so
    // its reference's two perturbation sizes agree to ~2e-3, not 1e-3.
    set.reference_agreement = std::max(tol, 1e-3);
    const SensitivityResult mixed = makeSensitivityMethod("mixed", set)->compute(p);
    const SensitivityResult ref = makeSensitivityMethod("reference", set)->compute(p);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(mixed.dpsi_db[i], ref.dpsi_db[i], 10 * tol * std::abs(ref.dpsi_db[i]) + 1e-9) << cost << " " << i;
  }
}

TEST(Sensitivity, MixedCarriesAuxiliaryStates) {
  // An extra z (an integral of x^2, standing for a tire's relaxation state)
  // joins x = (q, u, z) in the mixed method and leaves d psi / d b unchanged.
  SensitivitySettings set;
  set.tolerance = 1e-5;
  const SensitivityResult plain = makeSensitivityMethod("mixed", set)->compute(oscillatorProblem(false));
  const SensitivityResult withZ = makeSensitivityMethod("mixed", set)->compute(oscillatorProblem(true));
  ASSERT_EQ(plain.dpsi_db.size(), withZ.dpsi_db.size());
  for (std::size_t i = 0; i < plain.dpsi_db.size(); ++i)
    EXPECT_NEAR(withZ.dpsi_db[i], plain.dpsi_db[i], 2e-5 * std::abs(plain.dpsi_db[i])) << i;  // both within 1e-5
  EXPECT_EQ(withZ.dpsi_db.size(), 3u);
}

// The mixed method's "refinement" setting: uniform (every node interval
// bisected each pass, the default) and adaptive (only those with a large
// interpolation indicator) both meet the tolerance against the closed form,
// on different node sets.
TEST(Sensitivity, MixedRefinementUniformAndAdaptive) {
  const SensitivityProblem p = oscillatorProblem();
  const ClosedForm cf = closedForm(1, 100, 4);
  SensitivitySettings set;
  set.tolerance = 1e-6;
  EXPECT_EQ(set.refinement, MixedRefinement::Uniform);
  const SensitivityResult uniform = makeSensitivityMethod("mixed", set)->compute(p);
  set.refinement = MixedRefinement::Adaptive;
  const SensitivityResult adaptive = makeSensitivityMethod("mixed", set)->compute(p);
  ASSERT_EQ(uniform.dpsi_db.size(), 3u);
  ASSERT_EQ(adaptive.dpsi_db.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(uniform.dpsi_db[i] - cf.d[i]) / std::abs(cf.d[i]), 1e-5) << i;
    EXPECT_LT(std::abs(adaptive.dpsi_db[i] - cf.d[i]) / std::abs(cf.d[i]), 1e-5) << i;
    EXPECT_NEAR(adaptive.dpsi_db[i], uniform.dpsi_db[i], 2e-5 * std::abs(cf.d[i])) << i;
  }
  std::printf("  uniform: %d nodes, %d residual evaluations; adaptive: %d nodes, %d residual evaluations\n",
              uniform.grid_points, uniform.residual_evaluations, adaptive.grid_points, adaptive.residual_evaluations);
  EXPECT_NE(uniform.residual_evaluations, adaptive.residual_evaluations);
  EXPECT_NE(uniform.grid_points, adaptive.grid_points);
  EXPECT_EQ(mixedRefinementFromName("adaptive", "w"), MixedRefinement::Adaptive);
  EXPECT_EQ(mixedRefinementFromName("uniform", "w"), MixedRefinement::Uniform);
  try {
    mixedRefinementFromName("sometimes", "s.json: analysis.refinement");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "s.json: analysis.refinement: expected uniform or adaptive, got 'sometimes'");
  }
}

QuarterCarParams relaxationQuarterCar() {
  QuarterCarParams q = QuarterCarParams::fromFile("quarter_car.json");
  q.tire.params["relaxation_length_longitudinal_m"] = 0.25;
  q.tire.params["relaxation_length_lateral_m"] = 0.5;
  return q;
}

class ResidualJacobiansTest : public ::testing::TestWithParam<bool> {};

TEST_P(ResidualJacobiansTest, MatchForwardDynamics) {
  // The mixed method's u'_x = -[I 0] [M G^T; G 0]^-1 [R_x; a_x] (inverse
  // dynamics) against finite differences of Simbody's forward dynamics, on the
  // closed-loop quarter car in motion; with the relaxation tire x includes its
  // two patch deflections z (columns of R_x and rows z'_x).
  const bool relaxation = GetParam();
  QuarterCar car(relaxation ? relaxationQuarterCar() : QuarterCarParams::fromFile("quarter_car.json"));
  SimTK::State s = car.makeInitialState();
  SimulationSettings sim;
  sim.t_end_s = 0.13;
  simulate(car.getScene(), s, sim);
  const SimTK::State se = toEulerAngles(car.getScene(), s);
  SimTK::State work = se;
  const ResidualJacobians J = calcResidualJacobians(car.getScene(), se, work, true);
  EXPECT_EQ(se.getNZ(), relaxation ? 2 : 0);
  EXPECT_EQ(J.zdot_x.rows(), se.getNZ());
  EXPECT_EQ(J.R_x.cols(), se.getNQ() + se.getNU() + se.getNZ());
  const Eigen::MatrixXd A = calcSensitivityMatrix(J);
  const int nq = se.getNQ(), nu = se.getNU();
  EXPECT_EQ(J.G.rows(), 4);  // upper ball joint (3) and steer lock (1)
  const Eigen::MatrixXd fromResidual = A.middleRows(nq, nu), fromForward = J.udot_x;
  const double scale = fromForward.cwiseAbs().maxCoeff();
  const double err = (fromResidual - fromForward).cwiseAbs().maxCoeff() / scale;
  std::printf("  nq %d nu %d: max |u'_x(residual) - u'_x(forward dynamics)| / max |u'_x| = %.2e\n", nq, nu, err);
  EXPECT_LT(err, 1e-5);
  EXPECT_GT(scale, 1.0);
  if (relaxation) {
    // d u_x' / d u_x = -|Vx| / sigma_x (the patch relaxes at the wheel's speed).
    const int nz0 = nq + nu;
    EXPECT_LT(J.zdot_x(0, nz0), 0.0);
    EXPECT_GT(J.R_x.col(nz0).cwiseAbs().maxCoeff(), 1e3);  // the patch force acts on the wheel, N/m
  }
}
INSTANTIATE_TEST_SUITE_P(Sensitivity, ResidualJacobiansTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "RelaxationTire" : "SteadySlipTire"; });

TEST(Sensitivity, MixedAgreesWithTheReferenceOnTheQuarterCar) {
  SensitivityProblem p;
  p.model = QuarterCarDesign::fromFile("quarter_car.json");
  p.parameters = {"K", "m1", "s'"};
  p.cost = CostFunctional::parse("integral_of_square:chassis.az_m_s2");
  p.t_end_s = 0.2;
  p.integrator.accuracy = 1e-8;
  SensitivitySettings set;
  set.tolerance = 1e-4;
  const SensitivityResult mixed = makeSensitivityMethod("mixed", set)->compute(p);
  const SensitivityResult ref = makeSensitivityMethod("reference", set)->compute(p);
  for (std::size_t i = 0; i < 3; ++i) {
    const double rel = std::abs(mixed.dpsi_db[i] - ref.dpsi_db[i]) / std::abs(ref.dpsi_db[i]);
    std::printf("  %-32s mixed %.9g reference %.9g rel. error %.2e (mixed estimate %.1e)\n",
                mixed.parameters[i].c_str(), mixed.dpsi_db[i], ref.dpsi_db[i], rel,
                mixed.error_estimate[i] / std::abs(mixed.dpsi_db[i]));
    EXPECT_LT(rel, 1e-3) << mixed.parameters[i];
  }
  EXPECT_NEAR(mixed.psi / ref.psi, 1.0, 1e-5);
}

TEST(Sensitivity, MixedMeetsTheBarWithTheRelaxationTire) {
  // With the relaxation-length tire (z states) mixed reaches 1e-4 against the
  // reference; every parameter of the study, horizon shortened to 0.3 s.
  SensitivityProblem p;
  p.model = std::make_shared<QuarterCarDesign>(relaxationQuarterCar());
  p.parameters = {"m1", "m3", "K", "D", "Cz", "s'"};
  p.cost = CostFunctional::parse("integral_of_square:chassis.az_m_s2");
  p.t_end_s = 0.3;
  p.integrator.accuracy = 1e-9;
  SensitivitySettings set;
  set.tolerance = 1e-5;
  set.reference_perturbation = 1e-3;
  const SensitivityResult mixed = makeSensitivityMethod("mixed", set)->compute(p);
  const SensitivityResult ref = makeSensitivityMethod("reference", set)->compute(p);
  for (std::size_t i = 0; i < p.parameters.size(); ++i) {
    const double rel = std::abs(mixed.dpsi_db[i] - ref.dpsi_db[i]) / std::abs(ref.dpsi_db[i]);
    std::printf("  %-32s mixed %.9g reference %.9g rel. error %.2e (reference disagreement %.1e)\n",
                mixed.parameters[i].c_str(), mixed.dpsi_db[i], ref.dpsi_db[i], rel,
                ref.error_estimate[i] / std::abs(ref.dpsi_db[i]));
    EXPECT_LT(rel, 1e-4) << mixed.parameters[i];
    EXPECT_LT(ref.error_estimate[i], 1e-4 * std::abs(ref.dpsi_db[i])) << mixed.parameters[i];
  }
}

TEST(Sensitivity, UserErrorsNameTheCause) {
  SensitivityProblem p = oscillatorProblem();
  p.parameters = {"m", "mass"};
  EXPECT_EQ(test::errorOf([&] { p.validate(); }),
            "oscillator has no design parameter 'mass'; known: mass_kg, stiffness_N_per_m, damping_N_s_per_m");
  p.parameters = {"m", "mass_kg"};
  EXPECT_EQ(test::errorOf([&] { p.validate(); }),
            "sensitivity problem: design parameter 'mass_kg' is listed twice");
  EXPECT_EQ(test::errorOf([] { makeSensitivityMethod("adjoint"); }),
            "unknown sensitivity method 'adjoint'; known: fd_central, fd_forward, mixed, reference");
  EXPECT_EQ(test::errorOf([] { CostFunctional::parse("mean:x_m"); }),
            "unknown cost kind 'mean'; known: integral_of_square, maximum, final_value");
  EXPECT_EQ(test::errorOf([&] { p.model->build({1.0, NAN, 4.0}); }),
            "oscillator design parameter stiffness_N_per_m must be a finite number, got nan");
}
