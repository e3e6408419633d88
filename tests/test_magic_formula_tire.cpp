// The Magic Formula tire as a vdyn tire kind ("magic_formula"): the adapter
// evaluates calcMagicFormula at the contact's slips (bit for bit), mirrors on
// the other side, takes its vertical spring and rolling radius from the file,
// and, on the App. A vehicle at rest pushed sideways by 10 % of its weight,
// holds it with the file's relaxation lengths (creep under 1 mm/s).
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "vdyn/core/analysis.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/magic_formula/magic_formula_tire.h"
#include "vdyn/tire/tire_force.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
const char* kFile = "tires/pac2002_185_80R14.tir";

std::shared_ptr<const MagicFormulaTire> tire(WheelSide side, bool relaxation = false) {
  MagicFormulaTireParams p;
  p.file = kFile;
  p.relaxation = relaxation;
  return MagicFormulaTire::fromParams(p, side);
}

ContactKinematics contact(const TireModel& m, double fz, double vx, double vy, double kappa, double gamma) {
  ContactKinematics k;
  k.deflection_m = calcStaticDeflection(m, fz);
  k.vx_m_s = vx;
  k.vy_m_s = vy;
  k.spin_rad_s = vx * (1 + kappa) / m.calcRollingRadius(k.deflection_m);
  k.camber_rad = gamma;
  return k;
}
}  // namespace

TEST(MagicFormulaTire, EvaluatesTheFormulaAtTheContactSlips) {
  const auto m = tire(WheelSide::Right);
  const mf::MagicFormulaCoefficients& c = m->coefficients();
  for (double vx : {0.3, 5.0, 20.0, -8.0})
    for (double vy : {-1.0, 0.0, 0.4})
      for (double kappa : {-0.2, 0.0, 0.05})
        for (double gamma : {0.0, 0.03}) {
          const ContactKinematics k = contact(*m, 3000.0, vx, vy, kappa, gamma);
          const TireForces f = m->calcForces(k);
          // The slips of every tire kind (tire_model.h), with VXLOW as the low-speed threshold.
          const double Re = mf::calcEffectiveRollingRadius(c, c.VERTICAL_STIFFNESS * k.deflection_m, 0.0);
          const double den = std::max(std::abs(vx), c.VXLOW);
          mf::MagicFormulaInputs in;
          in.fz_N = c.VERTICAL_STIFFNESS * k.deflection_m;
          in.kappa = -(vx - k.spin_rad_s * Re) / den;
          in.tan_alpha = vy / den;
          in.gamma_rad = gamma;
          in.vx_m_s = vx;
          in.mounted_side = mf::TireSide::Right;
          const mf::MagicFormulaOutputs o = mf::calcMagicFormula(c, in);
          EXPECT_EQ(f.fz_N, in.fz_N);
          EXPECT_EQ(f.fx_N, o.fx_N) << vx << " " << vy << " " << kappa;
          EXPECT_EQ(f.fy_N, o.fy_N) << vx << " " << vy << " " << kappa;
          EXPECT_EQ(f.mz_N_m, o.mz_N_m);
          EXPECT_EQ(f.mx_N_m, o.mx_N_m);
          EXPECT_EQ(f.my_N_m, o.my_N_m);
          EXPECT_TRUE(std::isfinite(f.fx_N) && std::isfinite(f.fy_N) && std::isfinite(f.mz_N_m));
        }
}

TEST(MagicFormulaTire, LeftAndRightAreMirrorImages) {
  // The file is measured for the left side; a right wheel is its mirror (y -> -y).
  const auto left = tire(WheelSide::Left), right = tire(WheelSide::Right);
  for (double vy : {-0.8, 0.3})
    for (double gamma : {-0.02, 0.04}) {
      const TireForces l = left->calcForces(contact(*left, 3500.0, 15.0, vy, 0.03, gamma));
      const TireForces r = right->calcForces(contact(*right, 3500.0, 15.0, -vy, 0.03, -gamma));
      EXPECT_NEAR(r.fy_N, -l.fy_N, 1e-9 * std::abs(l.fy_N));
      EXPECT_NEAR(r.mz_N_m, -l.mz_N_m, 1e-9 * std::abs(l.mz_N_m) + 1e-12);
      EXPECT_NEAR(r.fx_N, l.fx_N, 1e-9 * std::abs(l.fx_N));
    }
  // And the file's asymmetry shows: a right wheel is not the left one.
  const TireForces l = left->calcForces(contact(*left, 3500.0, 15.0, 0.3, 0.0, 0.02));
  const TireForces r = right->calcForces(contact(*right, 3500.0, 15.0, 0.3, 0.0, 0.02));
  EXPECT_NE(l.fy_N, r.fy_N);
}

TEST(MagicFormulaTire, VerticalModelAndRelaxationFromTheFile) {
  const auto m = tire(WheelSide::Right, true);
  const mf::MagicFormulaCoefficients& c = m->coefficients();
  EXPECT_EQ(m->vertical().unloaded_radius_m, c.UNLOADED_RADIUS);
  EXPECT_EQ(m->vertical().radial_stiffness_N_per_m, c.VERTICAL_STIFFNESS);
  EXPECT_EQ(m->vertical().radial_damping_N_s_per_m, c.VERTICAL_DAMPING);
  EXPECT_EQ(m->slip().low_speed_threshold_m_s, c.VXLOW);
  ContactKinematics k;
  k.deflection_m = 0.01;
  EXPECT_EQ(m->calcNormalForce(k), c.VERTICAL_STIFFNESS * 0.01);
  EXPECT_EQ(m->calcRollingRadius(0.01), mf::calcEffectiveRollingRadius(c, c.VERTICAL_STIFFNESS * 0.01, 0.0));
  EXPECT_TRUE(m->hasRelaxation());
  for (double fz : {1000.0, 3800.0, 6000.0}) {
    const auto [sx, sy] = m->calcRelaxationLengths(fz);
    const mf::RelaxationLengths l = mf::calcRelaxationLengths(c, fz, 0.0);
    EXPECT_EQ(sx, l.longitudinal_m);
    EXPECT_EQ(sy, l.lateral_m);
    EXPECT_GT(sx, 0.0);
    EXPECT_GT(sy, 0.0);
  }
  EXPECT_FALSE(tire(WheelSide::Right, false)->hasRelaxation());
}

TEST(MagicFormulaTire, UnknownFileAndKeysAreNamed) {
  MagicFormulaTireParams p;
  try {
    p.validate("car.json: tire.params");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "car.json: tire.params.file: a .tir property file is required");
  }
  p.file = "tires/none.tir";
  try {
    MagicFormulaTire::fromParams(p, WheelSide::Left);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("none.tir"), std::string::npos) << e.what();
  }
}

// The App. A vehicle at rest on the Magic Formula tires with relaxation, pushed
// sideways (ground +y) by 10 % of its weight from t = 0 (0.5 s rise), wheels
// held straight: once settled (2 s to 10 s) it creeps sideways by less than
// 1 mm/s. (The wheels are not braked: along x the car is free to roll.)
TEST(MagicFormulaTire, AtRestPushedSidewaysItCreepsUnderOneMillimetrePerSecond) {
  const WheeledVehicleParams data = WheeledVehicleParams::fromFile("appendix_a_mf.json");
  const WheeledVehicle car(data);
  const double weight = car.totalMass() * data.gravity_m_per_s2;
  Json scene = R"({"name": "creep", "vehicle": {"type": "fourws", "data": "appendix_a_mf.json", "initial_speed_m_s": 0},
    "plugins": [
      {"kind": "constraint", "type": "steering", "name": "front_steer", "attach": "front_axle",
       "command": {"type": "hold", "angle_rad": 0}},
      {"kind": "constraint", "type": "steering", "name": "rear_steer", "attach": "rear_axle",
       "command": {"type": "hold", "angle_rad": 0}},
      {"type": "body_force", "name": "push", "attach": "chassis", "force_N": [0, 0, 0], "rise_time_s": 0.5}],
    "outputs": ["chassis.y_m"],
    "analysis": {"type": "transient", "t_end_s": 10.0, "report_interval_s": 1.0,
                 "integrator": {"method": "rk_merson", "accuracy": 1e-6, "constraint_tolerance": 1e-10}}})"_json;
  scene["plugins"][2]["force_N"] = {0.0, 0.1 * weight, 0.0};
  const SceneDescription d = SceneDescription::fromJson(scene, "creep.json", standardRegistry());
  BuiltScene b = d.build();
  const AnalysisResult r = b.analysis->run(AnalysisContext{d, b, "", {}});
  const Table* history = nullptr;
  for (const auto& [n, t] : r.tables)
    if (n == "history") history = &t;
  ASSERT_NE(history, nullptr);
  std::size_t iy = 0;
  while (history->columns.at(iy) != "chassis.y_m") ++iy;
  auto yAt = [&](double t) {
    for (const auto& row : history->rows)
      if (std::abs(row[0] - t) < 1e-9) return row[iy];
    throw Error("no row at t = " + std::to_string(t));
  };
  const double y2 = yAt(2.0), y10 = yAt(10.0);
  std::printf("push %.1f N: y(2 s) = %.6e m, y(10 s) = %.6e m, mean creep %.3e m/s\n", 0.1 * weight, y2, y10,
              (y10 - y2) / 8);
  EXPECT_GT(y2, 0.0);  // it gave way in the direction of the push, then held
  for (double t = 3.0; t <= 10.0; t += 1.0) EXPECT_LT(std::abs(yAt(t) - yAt(t - 1.0)), 1e-3) << t;
  EXPECT_LT(std::abs(y10 - y2) / 8, 1e-3);
}
