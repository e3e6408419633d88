// The waveform steering commands (plugins/steering, commands.h): each against
// its closed form, its rate and acceleration against central differences of
// its angle and rate, continuity where the pieces join, and bad data named.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "test_util.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/simulation.h"
#include "vdyn/steering/steering.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {
const double kPi = SimTK::Pi;

std::shared_ptr<const SteeringCommand> make(const Json& j) {
  return makeSteeringCommand(ParamReader::fromJson(j, "cmd.json: command"));
}

/// Largest |rate - d angle/dt| and |accel - d rate/dt| (central differences,
/// step h) over the times `ts`, relative to `scale` (rad/s, rad/s^2).
void expectDerivatives(const SteeringCommand& c, const std::vector<double>& ts, double tol_rate, double tol_accel) {
  const double h = 1e-6;
  for (double t : ts) {
    const SteerCommandValue v = c.calcAt(t), p = c.calcAt(t + h), m = c.calcAt(t - h);
    EXPECT_NEAR(v.rate_rad_s, (p.angle_rad - m.angle_rad) / (2 * h), tol_rate) << "t " << t;
    EXPECT_NEAR(v.accel_rad_s2, (p.rate_rad_s - m.rate_rad_s) / (2 * h), tol_accel) << "t " << t;
  }
}

std::vector<double> grid(double a, double b, int n) {
  std::vector<double> t;
  for (int i = 0; i <= n; ++i) t.push_back(a + (b - a) * (i + 0.37) / (n + 1));  // off the joints
  return t;
}
}  // namespace

// Ramp 0 -> 0.1 rad at 0.2 rad/s from t = 1 s, blended over 0.1 s: duration
// 0.1/0.2 + 0.1 = 0.6 s; mid-ramp angle R (tau - b/2); rate R; ends held.
TEST(SteeringCommands, RampClosedForm) {
  const auto c = make({{"type", "ramp"}, {"initial_rad", 0.0}, {"final_rad", 0.1}, {"rate_rad_s", 0.2},
                       {"start_time_s", 1.0}, {"blend_s", 0.1}});
  EXPECT_EQ(c->calcAt(0.5).angle_rad, 0.0);
  EXPECT_NEAR(c->calcAt(1.3).angle_rad, 0.2 * (0.3 - 0.05), 1e-15);
  EXPECT_NEAR(c->calcAt(1.3).rate_rad_s, 0.2, 1e-15);
  EXPECT_NEAR(c->calcAt(1.05).angle_rad, 0.2 * 0.1 * (0.125 - 0.5 * 0.0625), 1e-15);  // u = 1/2
  EXPECT_NEAR(c->calcAt(1.05).rate_rad_s, 0.1, 1e-15);                              // R h(1/2)
  EXPECT_EQ(c->calcAt(1.6).angle_rad, 0.1);
  EXPECT_EQ(c->calcAt(2.0).rate_rad_s, 0.0);
  for (double tj : {1.0, 1.1, 1.5, 1.6}) {  // joins: angle, rate continuous
    const SteerCommandValue a = c->calcAt(tj - 1e-12), b = c->calcAt(tj + 1e-12);
    EXPECT_NEAR(a.angle_rad, b.angle_rad, 1e-12) << tj;
    EXPECT_NEAR(a.rate_rad_s, b.rate_rad_s, 1e-10) << tj;
  }
  expectDerivatives(*c, grid(0.9, 1.7, 40), 1e-8, 2e-5);
  EXPECT_NE(errorOf([] { make({{"type", "ramp"}, {"final_rad", 0.1}, {"rate_rad_s", -0.2}}); }).find("rate_rad_s"),
            std::string::npos);
  EXPECT_NE(errorOf([] {
              make({{"type", "ramp"}, {"final_rad", 0.01}, {"rate_rad_s", 0.2}, {"blend_s", 0.1}});
            }).find("blend_s = 0.1 s must be at most"),
            std::string::npos);
}

// Sine 0.02 rad at 0.5 Hz for 2 cycles from t = 1 s about 0.01 rad.
TEST(SteeringCommands, SineClosedFormAndFade) {
  const auto c = make({{"type", "sine"}, {"offset_rad", 0.01}, {"amplitude_rad", 0.02}, {"frequency_Hz", 0.5},
                       {"start_time_s", 1.0}, {"cycles", 2}});
  for (double t : {1.2, 2.0, 3.7, 4.9}) {
    const double w = 2 * kPi * 0.5, tau = t - 1;
    EXPECT_NEAR(c->calcAt(t).angle_rad, 0.01 + 0.02 * std::sin(w * tau), 1e-15);
    EXPECT_NEAR(c->calcAt(t).rate_rad_s, 0.02 * w * std::cos(w * tau), 1e-15);
    EXPECT_NEAR(c->calcAt(t).accel_rad_s2, -0.02 * w * w * std::sin(w * tau), 1e-15);
  }
  EXPECT_EQ(c->calcAt(5.5).angle_rad, 0.01);
  // Faded over one period at each end of four: the rate starts and ends at 0
  // and the middle periods are the plain sine.
  const auto f = make({{"type", "sine"}, {"amplitude_rad", 0.02}, {"frequency_Hz", 1.0}, {"cycles", 4},
                       {"fade_cycles", 1}});
  EXPECT_NEAR(f->calcAt(1e-9).rate_rad_s, 0.0, 1e-9);
  EXPECT_NEAR(f->calcAt(4 - 1e-9).rate_rad_s, 0.0, 1e-9);
  EXPECT_NEAR(f->calcAt(1.6).angle_rad, 0.02 * std::sin(2 * kPi * 1.6), 1e-15);
  expectDerivatives(*f, grid(0.0, 4.0, 80), 1e-8, 1e-5);
  EXPECT_NE(errorOf([] { make({{"type", "sine"}, {"amplitude_rad", 0.9}, {"frequency_Hz", 1.0}}); })
                .find("amplitude_rad + |offset_rad| must lie in"),
            std::string::npos);
}

// Chirp 0.1 -> 2 Hz over 10 s: the phase at T/2 is 2 pi (f0 T/2 + (f1 - f0) T/8).
TEST(SteeringCommands, ChirpClosedForm) {
  const auto c = make({{"type", "chirp"}, {"amplitude_rad", 0.01}, {"start_frequency_Hz", 0.1},
                       {"end_frequency_Hz", 2.0}, {"duration_s", 10.0}, {"fade_s", 1.0}});
  const double phi = 2 * kPi * (0.1 * 5 + 1.9 * 10 / 8);
  EXPECT_NEAR(c->calcAt(5.0).angle_rad, 0.01 * std::sin(phi), 1e-15);
  EXPECT_NEAR(c->calcAt(5.0).rate_rad_s, 0.01 * std::cos(phi) * 2 * kPi * (0.1 + 1.9 * 0.5), 1e-14);
  EXPECT_NEAR(c->calcAt(1e-9).rate_rad_s, 0.0, 1e-9);
  EXPECT_EQ(c->calcAt(10.5).angle_rad, 0.0);
  expectDerivatives(*c, grid(0.0, 10.0, 200), 1e-8, 5e-5);
}

// FMVSS 126: 0.7 Hz; the first peak A at 1/(4f), -A from 3/(4f) through the
// dwell, zero at 1/f + dwell; rate continuous at the dwell's ends.
TEST(SteeringCommands, SineWithDwellClosedForm) {
  const auto c = make({{"type", "sine_with_dwell"}, {"amplitude_rad", 0.05}, {"start_time_s", 1.0}});
  const double f = 0.7, T = 1 / f;
  EXPECT_NEAR(c->calcAt(1 + 0.25 * T).angle_rad, 0.05, 1e-15);
  EXPECT_NEAR(c->calcAt(1 + 0.75 * T).angle_rad, -0.05, 1e-15);
  EXPECT_NEAR(c->calcAt(1 + 0.75 * T + 0.3).angle_rad, -0.05, 1e-15);
  EXPECT_NEAR(c->calcAt(1 + 0.75 * T + 0.5 + 0.1).angle_rad, 0.05 * std::sin(2 * kPi * f * (0.75 * T + 0.1)), 1e-15);
  EXPECT_EQ(c->calcAt(1 + T + 0.5 + 1e-9).angle_rad, 0.0);
  for (double tj : {1 + 0.75 * T, 1 + 0.75 * T + 0.5}) {
    EXPECT_NEAR(c->calcAt(tj - 1e-10).rate_rad_s, c->calcAt(tj + 1e-10).rate_rad_s, 1e-9) << tj;
    EXPECT_NEAR(c->calcAt(tj - 1e-10).angle_rad, c->calcAt(tj + 1e-10).angle_rad, 1e-12) << tj;
  }
  expectDerivatives(*c, grid(1.0, 1 + T + 0.5, 60), 1e-8, 2e-5);
}

// A table: linear interpolation exact between rows; the clamped cubic spline
// starts and ends at zero rate and reproduces a finely sampled smooth
// manoeuvre (0.015 (1 - cos(pi t / 2)), at rest at both ends) to 1e-9;
// the first / last value held outside; bad files named with their line.
TEST(SteeringCommands, TableInterpolatesAndNamesBadRows) {
  const std::string dir = std::string(VDYN_TEST_OUT_DIR) + "/steer_table";
  std::system(("mkdir -p " + dir).c_str());
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + "/" + name) << text;
    return dir + "/" + name;
  };
  const std::string lin = write("lin.csv", "time_s,angle_rad\n0,0\n1,0.02\n3,0.06\n");
  const auto l = make({{"type", "table"}, {"file", lin}, {"interpolation", "linear"}});
  EXPECT_NEAR(l->calcAt(0.5).angle_rad, 0.01, 1e-16);
  EXPECT_NEAR(l->calcAt(2.0).angle_rad, 0.04, 1e-16);
  EXPECT_NEAR(l->calcAt(2.0).rate_rad_s, 0.02, 1e-16);
  EXPECT_EQ(l->calcAt(5.0).angle_rad, 0.06);
  EXPECT_EQ(l->calcAt(-1.0).angle_rad, 0.0);
  const auto lc = make({{"type", "table"}, {"file", lin}});  // cubic: through every row, at rest at the ends
  EXPECT_NEAR(lc->calcAt(1.0).angle_rad, 0.02, 1e-16);
  EXPECT_NEAR(lc->calcAt(1e-12).rate_rad_s, 0.0, 1e-12);
  EXPECT_NEAR(lc->calcAt(3.0 - 1e-12).rate_rad_s, 0.0, 1e-12);
  std::string sine = "time_s,angle_rad\n";
  for (int i = 0; i <= 400; ++i) {
    char row[64];
    std::snprintf(row, sizeof row, "%.17g,%.17g\n", i * 0.01, 0.015 * (1 - std::cos(kPi * i * 0.01 / 2)));
    sine += row;
  }
  const auto s = make({{"type", "table"}, {"file", write("sine.csv", sine)}});
  double err = 0;
  for (double t = 0.0; t < 4.0; t += 0.0037)
    err = std::max(err, std::abs(s->calcAt(t).angle_rad - 0.015 * (1 - std::cos(kPi * t / 2))));
  // The spline's interpolation error (5/384) h^4 max|y^(4)| = 1.2e-12 here.
  EXPECT_LT(err, 1e-9);
  expectDerivatives(*s, grid(0.0, 4.0, 50), 1e-8, 1e-4);
  EXPECT_NE(errorOf([&] { make({{"type", "table"}, {"file", write("b1.csv", "t,angle_rad\n0,0\n1,0\n")}}); })
                .find("b1.csv:1: the header needs columns time_s and angle_rad"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { make({{"type", "table"}, {"file", write("b2.csv", "time_s,angle_rad\n0,0\n1,0\n1,0.1\n")}}); })
                .find("b2.csv:4: time_s 1 does not follow the previous 1"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { make({{"type", "table"}, {"file", write("b3.csv", "time_s,angle_rad\n0,0\n1,x\n")}}); })
                .find("b3.csv:3: angle_rad 'x' is not a finite number"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { make({{"type", "table"}, {"file", write("b4.csv", "time_s,angle_rad\n0,0\n")}}); })
                .find("at least 2 rows, got 1"),
            std::string::npos);
}

// A command drives the steering plugin: App. A's front wheels follow a faded
// sine to the constraint tolerance through a 2 s run at 10 m/s.
TEST(SteeringCommands, FrontWheelsFollowAFadedSine) {
  // Simbody's steering rows, projected at the constraint tolerance, hold the
  // angle on the command to 1e-8; the dense rows (formulation auto) hold it by
  // Baumgarte terms at the integrator's level (3e-8 at accuracy 1e-6), so
  // this claim is the constrained model's.
  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a.json");
  p.formulation = "constrained";
  WheeledVehicle car(p);
  const auto cmd = make({{"type", "sine"}, {"amplitude_rad", 0.02}, {"frequency_Hz", 1.0}, {"start_time_s", 0.2},
                         {"cycles", 1.5}, {"fade_cycles", 0.5}});
  car.addAxleSteering("front_steer", "front", cmd);
  car.addAxleSteering("rear_steer", "rear", make({{"type", "hold"}, {"angle_rad", 0.0}}));
  SimTK::State s = car.makeInitialState(10.0);
  SimulationSettings sim;
  sim.t_end_s = 2.0;
  sim.report_interval_s = 0.05;
  sim.integrator.accuracy = 1e-6;
  double worst = 0, peakYaw = 0;
  simulate(car.getScene(), s, sim, nullptr, [&](const SimTK::State& st) {
    worst = std::max(worst, std::abs(car.getScene().evalOutput("front_steer.angle_rad", st) - cmd->calc(st).angle_rad));
    peakYaw = std::max(peakYaw, std::abs(car.getScene().evalOutput("chassis.yaw_rate_rad_s", st)));
  });
  EXPECT_LT(worst, 1e-8);
  EXPECT_GT(peakYaw, 1e-2);  // it steered the car
}

// A command whose rate jumps (a sine without a fade, FMVSS 126's sine with
// dwell, a linear table) runs in a transient analysis: the integrator restarts
// at each jump (SimulationSettings::restart_times_s from the plugin), the
// wheels follow the command, and without the restarts no step passes the jump.
TEST(SteeringCommands, RateJumpsRestartTheIntegrator) {
  PluginRegistry& reg = standardRegistry();
  const SceneDescription base = SceneDescription::fromFile("scenes/ch3_transient.json", reg);
  RunOptions opt;
  opt.plots = false;
  for (const Json& c : {Json{{"type", "sine"}, {"amplitude_rad", 0.03}, {"frequency_Hz", 1.0}, {"cycles", 1.25},
                             {"start_time_s", 0.5}},
                        Json{{"type", "sine_with_dwell"}, {"amplitude_rad", 0.04}, {"start_time_s", 0.5}}}) {
    const Json s = runScene(base.withOverrides({{"plugins.front_steer.command", c}, {"analysis.t_end_s", 2.5}}), opt);
    EXPECT_NEAR(s.at("peak_abs").at("front_steer.angle_rad").get<double>(), c.at("amplitude_rad").get<double>(), 1e-6)
        << c.dump();
    EXPECT_NEAR(s.at("final").at("front_steer.angle_rad").get<double>(),
                s.at("final").at("front_steer.command_rad").get<double>(), 1e-8)
        << c.dump();
  }
  // The same sine with the restart removed: the step at the jump cannot be taken.
  BuiltScene built = base.withOverride("plugins.front_steer.command", Json{{"type", "sine"}, {"amplitude_rad", 0.03},
                                                                           {"frequency_Hz", 1.0}, {"start_time_s", 0.5}})
                         .build();
  SimTK::State st = built.makeInitialState();
  SimulationSettings sim = TransientSettings::fields()
                               .read(ParamReader::fromJson(base.json().at("analysis"), "ch3_transient analysis"))
                               .simulation();  // the scene's integrator, rk_merson at 5e-7
  sim.t_end_s = 1.0;
  ASSERT_TRUE(sim.restart_times_s.empty());
  const std::string e = errorOf([&] { simulate(built.scene(), st, sim); });
  EXPECT_NE(e.find("Unable to advance time past 0.5"), std::string::npos) << e;
}
