// One composition path: every analysis runs on the scene's built scene, with
// the scene's plugins and plugin-library types. A body_force in the ISO 4138
// scene shows in the speed hold's force as its closed form says; a tire from a
// plugin library (plugin_fixture/tire.cpp) reaches every registered analysis.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "vdyn/core/plugin_library.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/handling_vehicles.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
const double kDeg = SimTK::Pi / 180;

/// The standard registry with the fixture tire library loaded.
PluginRegistry& registry() {
  PluginRegistry& r = standardRegistry();
  loadPluginLibrary(VDYN_FIXTURE_TIRE, r);
  return r;
}

/// Runs the scene's analysis on its built scene and returns the result
/// (tables included), as runScene does.
AnalysisResult runAnalysis(const SceneDescription& d) {
  BuiltScene b = d.build();
  const AnalysisContext ctx{d, b, "", {}};
  return b.analysis->run(ctx);
}

const Table& tableOf(const AnalysisResult& r, const std::string& name) {
  for (const auto& [n, t] : r.tables)
    if (n == name) return t;
  throw Error("no table " + name);
}

double cell(const Table& t, std::size_t row, const std::string& column) {
  for (std::size_t c = 0; c < t.columns.size(); ++c)
    if (t.columns[c] == column) return t.rows.at(row).at(c);
  throw Error("no column " + column);
}

/// ISO 4138 on the App. A vehicle at one speed (10 m/s on R = 100 m), with `plugins` as the scene's plugins.
SceneDescription iso4138At10(const Json& plugins) {
  std::vector<Override> ov = {{"analysis.speed_start_m_s", 10.0}, {"analysis.speed_max_m_s", 10.0},
                              {"analysis.stability", false}};
  if (!plugins.empty()) ov.push_back({"plugins", plugins});
  return SceneDescription::fromFile("scenes/iso4138_fourws.json", registry(), ov);
}

Json bodyForce(double fx, double fy) {
  return Json::array({{{"type", "body_force"}, {"name", "push"}, {"attach", "chassis"}, {"frame", "body"},
                       {"point_m", {0.0, 0.0, 0.0}}, {"force_N", {fx, fy, 0.0}}}});
}
}  // namespace

// The speed hold acts at the chassis origin along the horizontal velocity
// direction (v_xi e_xi + v_eta e_eta) / U0 in the chassis frame, i.e. at the
// side slip angle beta = atan2(v_eta, v_xi) from the chassis x axis; its force
// is + propulsive (speed_hold.h). A body-fixed force F (cos beta, sin beta, 0)
// at the chassis origin acts on the same line: the steady turn is unchanged
// and the hold supplies exactly F less: F_hold(pushed) = F_hold(plain) - F.
TEST(Composition, Iso4138BodyForceAlongTheTravelLowersTheSpeedHoldForceByIt) {
  const double F = 3000;
  const AnalysisResult plain = runAnalysis(iso4138At10(Json::array()));
  const Table& t0 = tableOf(plain, "iso4138");
  ASSERT_EQ(t0.rows.size(), 1u);
  const double beta = cell(t0, 0, "side_slip_deg") * kDeg;
  const AnalysisResult pushed = runAnalysis(iso4138At10(bodyForce(F * std::cos(beta), F * std::sin(beta))));
  const Table& t1 = tableOf(pushed, "iso4138");
  ASSERT_EQ(t1.rows.size(), 1u);
  const double h0 = cell(t0, 0, "speed_hold_force_N"), h1 = cell(t1, 0, "speed_hold_force_N");
  std::printf("beta %.6e rad; speed hold %.9f N plain, %.9f N pushed: difference %.9f N (F = %g N)\n", beta, h0, h1,
              h0 - h1, F);
  EXPECT_GT(h0, 0.0);  // the tires' drag in the turn
  EXPECT_NEAR(h0 - h1, F, 1e-8 * F);  // measured: 8e-9 N of 3000 N
  EXPECT_NEAR(cell(t1, 0, "front_deg"), cell(t0, 0, "front_deg"), 1e-7);
  EXPECT_NEAR(cell(t1, 0, "side_slip_deg"), cell(t0, 0, "side_slip_deg"), 1e-7);
  // The summary says which plugins the analysis added to the scene's.
  EXPECT_EQ(pushed.summary.at("plugins").at("added").dump(),
            R"x(["front_steer (steering)","rear_steer (steering)","speed_hold (speed_hold)"])x");
  EXPECT_TRUE(pushed.summary.at("plugins").at("replaced").empty());
}

// The issue's case: 3 kN along the chassis x axis (not the travel direction)
// changes the table: the hold force drops by F cos(beta) up to the change the
// lateral part F sin(beta) makes to the tires' drag.
TEST(Composition, Iso4138BodyForceAlongChassisXChangesTheTable) {
  const double F = 3000;
  const AnalysisResult plain = runAnalysis(iso4138At10(Json::array()));
  const AnalysisResult pushed = runAnalysis(iso4138At10(bodyForce(F, 0)));
  const Table &t0 = tableOf(plain, "iso4138"), &t1 = tableOf(pushed, "iso4138");
  const double d = cell(t0, 0, "speed_hold_force_N") - cell(t1, 0, "speed_hold_force_N");
  std::printf("chassis-x push: hold force difference %.6f N, front %.9f -> %.9f deg\n", d, cell(t0, 0, "front_deg"),
              cell(t1, 0, "front_deg"));
  EXPECT_NEAR(d, F, 1e-3 * F);  // measured: 0.19 N less
  EXPECT_NE(cell(t0, 0, "front_deg"), cell(t1, 0, "front_deg"));
}

// A scene's own steering, speed hold and controllers are replaced by the
// test's (named in the summary); the rest of its plugins stay.
TEST(Composition, HandlingAnalysisReplacesTheScenesSteeringAndSpeedHold) {
  const Json plugins = R"([
    {"type": "steering", "name": "front_steer", "attach": "front_axle", "command": {"type": "hold", "angle_rad": 0.1}},
    {"type": "speed_hold", "name": "hold", "attach": "chassis", "speed_m_s": 30},
    {"type": "body_force", "name": "push", "attach": "chassis", "force_N": [0, 0, 0]}])"_json;
  const AnalysisResult a = runAnalysis(iso4138At10(plugins)), b = runAnalysis(iso4138At10(Json::array()));
  EXPECT_EQ(a.summary.at("plugins").at("replaced").dump(), R"x(["front_steer (steering)","hold (speed_hold)"])x");
  // A zero force changes nothing: the same numbers as the scene without plugins.
  EXPECT_EQ(cell(tableOf(a, "iso4138"), 0, "front_deg"), cell(tableOf(b, "iso4138"), 0, "front_deg"));
}

// --- A tire from a plugin library in every registered analysis -------------
namespace {
/// The summary without wall/CPU times.
Json withoutTimes(Json j) {
  if (j.is_object()) {
    Json out = Json::object();
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.key().find("wall") == std::string::npos && it.key().find("cpu") == std::string::npos)
        out[it.key()] = withoutTimes(it.value());
    return out;
  }
  if (j.is_array())
    for (auto& e : j) e = withoutTimes(e);
  return j;
}

Json runWithTire(Json scene, const std::string& tire) {
  // The linear tires have no friction limit: mu keys removed where the block is (merge patch null).
  scene["vehicle"]["overrides"]["tire"] = {{"plugin", tire}, {"params", {{"mu_max", nullptr}, {"mu_min", nullptr}}}};
  return withoutTimes(runScene(SceneDescription::fromJson(scene, "composition.json", registry())));
}

/// The analysis runs with the built-in linear tire and with the library's
/// (stiffer) one, and its summary depends on which.
void expectTireReaches(const Json& scene) {
  const Json builtin = runWithTire(scene, "linear"), library = runWithTire(scene, "fixture_stiff_linear");
  EXPECT_NE(builtin.dump(), library.dump()) << scene.at("analysis").at("type");
}

Json bicycleScene(const Json& analysis, double steer_rad = 0.03) {
  Json j = R"({"name": "composition", "vehicle": {"type": "bicycle", "data": "bicycle.json", "initial_speed_m_s": 10},
    "plugins": [{"type": "speed_hold", "name": "speed_hold", "attach": "chassis", "speed_m_s": 10}]})"_json;
  j["plugins"].insert(j["plugins"].begin(), Json{{"type", "steering"}, {"name", "front_steer"}, {"attach", "front_axle"},
                                                 {"command", {{"type", "hold"}, {"angle_rad", steer_rad}}}});
  j["analysis"] = analysis;
  return j;
}

Json quarterCarScene(const Json& analysis) {
  Json j = R"({"name": "composition", "vehicle": {"type": "quarter_car", "data": "quarter_car.json"}})"_json;
  j["analysis"] = analysis;
  return j;
}
}  // namespace

TEST(Composition, LibraryTireInTransient) {
  Json s = bicycleScene(R"({"type": "transient", "t_end_s": 0.5, "report_interval_s": 0.05})"_json);
  s["plugins"][0]["command"] = R"({"type": "smooth_step", "initial_rad": 0, "final_rad": 0.03,
                                   "start_time_s": 0.05, "duration_s": 0.3})"_json;
  s["outputs"] = {"chassis.yaw_rate_rad_s"};
  expectTireReaches(s);
}
TEST(Composition, LibraryTireInStaticEquilibrium) {
  expectTireReaches(quarterCarScene(R"({"type": "static_equilibrium", "ineffective_bodies": ["wheel"]})"_json));
}
TEST(Composition, LibraryTireInSteadyState) {
  expectTireReaches(bicycleScene(R"({"type": "steady_state"})"_json));
}
TEST(Composition, LibraryTireInStability) {
  expectTireReaches(bicycleScene(R"({"type": "stability"})"_json));
}
TEST(Composition, LibraryTireInContinuation) {
  Json s = bicycleScene(
      R"({"type": "continuation", "plugin": "front_steer", "key": "angle_rad", "values": [0.01, 0.02]})"_json);
  s["outputs"] = {"chassis.yaw_rate_rad_s"};  // tabulated per point
  expectTireReaches(s);
}
TEST(Composition, LibraryTireInSensitivity) {
  expectTireReaches(quarterCarScene(R"({"type": "sensitivity",
      "parameters": [{"path": "vehicle.data.chassis_mass_kg", "name": "chassis_mass_kg", "scale": 100}],
      "cost": "integral_of_square:chassis.az_m_s2", "methods": ["fd_forward"], "t_end_s": 0.2})"_json));
}
TEST(Composition, LibraryTireInOptimalRatio) {
  Json s = R"({"name": "composition", "vehicle": {"type": "fourws", "data": "appendix_a.json", "initial_speed_m_s": 20.0},
    "plugins": [
      {"type": "steering", "name": "front_steer", "attach": "front_axle", "command": {"type": "hold", "angle_rad": 0}},
      {"type": "steering", "name": "rear_steer", "attach": "rear_axle", "command": {"type": "hold", "angle_rad": 0}},
      {"type": "speed_hold", "name": "speed_hold", "attach": "chassis", "speed_m_s": 20.0}],
    "analysis": {"type": "optimal_ratio", "front_angles_rad": [0.008726646259971648, 0.017453292519943295]}})"_json;
  expectTireReaches(s);
}
TEST(Composition, LibraryTireInIso4138MatchesTheLinearBicycleClosedForm) {
  const Json s = bicycleScene(R"({"type": "iso4138_constant_radius", "radius_m": 100, "speed_start_m_s": 3,
      "speed_step_m_s": 1, "speed_max_m_s": 8, "stability": false})"_json);
  expectTireReaches(s);
  // Linear bicycle (6.1)-(6.9), two tires per axle of cornering stiffness
  // 2 x the data's: K = M / l (b / C - a / C), C = 2 (2 C_alpha).
  Json lib = s;
  lib["vehicle"]["overrides"]["tire"]["plugin"] = "fixture_stiff_linear";
  const SceneDescription d = SceneDescription::fromJson(lib, "composition.json", registry());
  const BuiltScene b = d.build();
  const Bicycle& bk = b.vehicleAs<Bicycle>();
  const double M = bk.totalMass(), a = bk.distanceToFrontAxle(), bb = bk.distanceToRearAxle(), l = a + bb;
  const double C = 2 * 2 * LinearTireParams::fromParams(ParamReader::fromJson(bk.params().tire.params, "t")).cornering_stiffness_N_per_rad;
  const double K = M / l * (bb / C - a / C);
  const Json r = runScene(d);
  std::printf("library tire: understeer gradient %.6e rad/(m/s^2), closed form %.6e\n",
              r.at("understeer_gradient_linear_deg_per_m_s2").get<double>() * kDeg, K);
  EXPECT_NEAR(r.at("understeer_gradient_linear_deg_per_m_s2").get<double>() * kDeg, K, 1e-3 * std::abs(K));
}
TEST(Composition, LibraryTireInIso7401) {
  expectTireReaches(bicycleScene(R"({"type": "iso7401", "speed_m_s": 15, "lateral_accel_m_s2": 2, "duration_s": 1,
      "frequency_from_Hz": 0.5, "frequency_to_Hz": 2, "frequency_count": 3})"_json));
}
TEST(Composition, LibraryTireInSineWithDwell) {
  expectTireReaches(bicycleScene(R"({"type": "sine_with_dwell", "speed_m_s": 15, "lateral_accel_m_s2": 2.943,
      "first_factor": 1.5, "max_amplitude_factor": 1.5, "after_s": 1.75})"_json));
}
TEST(Composition, LibraryTireInIso3888) {
  Json s = R"({"name": "composition", "vehicle": {"type": "bicycle", "data": "bicycle.json", "initial_speed_m_s": 10.0},
    "plugins": [
      {"type": "steering", "name": "front_steer", "attach": "front_axle", "command": {"type": "state"}},
      {"type": "path_control", "name": "path_control", "attach": "chassis", "steering": "front_steer",
       "path": {"type": "lane_change", "start_x_m": 30.0, "length_m": 40.0, "shift_m": 3.5},
       "gains": {"k1_rad_per_s2_per_m": 10, "k2_rad_per_s2": 2, "k3_rad_per_s2_per_m": 100, "k4_rad_per_s2": 5,
                 "k5_per_s": 20, "look_ahead_s": 0.3, "tracked_point_m": [0.0, 0.0, -0.59]}}],
    "analysis": {"type": "iso3888_2", "speed_low_m_s": 8.0, "speed_high_m_s": 9.0, "speed_tolerance_m_s": 1.0}})"_json;
  expectTireReaches(s);
}
TEST(Composition, LibraryTireInVehicleReport) {
  expectTireReaches(quarterCarScene(R"({"type": "vehicle_report", "travel_range_m": 0.02, "travel_step_m": 0.01})"_json));
}

// limit_map: the linear tires have no friction limit, so the steady turn has
// no fold in the front angle; with either tire the map stops with the named
// error (the library tire reached the solver: the branch was followed on it).
TEST(Composition, LibraryTireInLimitMap) {
  for (const char* tire : {"linear", "fixture_stiff_linear"}) {
    Json s = bicycleScene(R"({"type": "limit_map", "speed_start_m_s": 10, "speed_max_m_s": 12,
        "front_step_rad": 0.01, "front_max_rad": 0.03, "stability": false})"_json);
    s["vehicle"]["overrides"]["tire"] = {{"plugin", tire}, {"params", {{"mu_max", nullptr}, {"mu_min", nullptr}}}};
    try {
      runScene(SceneDescription::fromJson(s, "composition.json", registry()));
      ADD_FAILURE() << tire << ": a fold on linear tires";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("no fold of the steady turn in the front angle"), std::string::npos)
          << e.what();
    }
  }
}

// Every registered analysis type has a test above (a new one must add its own).
TEST(Composition, EveryRegisteredAnalysisIsCovered) {
  const std::vector<std::string> covered = {"continuation", "iso3888_2", "iso4138_constant_radius", "iso7401",
                                            "limit_map", "optimal_ratio", "sensitivity", "sine_with_dwell", "stability",
                                            "static_equilibrium", "steady_state", "transient", "vehicle_report"};
  std::vector<std::string> known = registry().known(PluginKind::Analysis);
  std::sort(known.begin(), known.end());
  EXPECT_EQ(known, covered);
}
