// The chapter 3 design sweep near the limit of adhesion (issue 22): the steady
// turn (front 4 deg, rear 1 deg, App. A 4WS vehicle) at 15 m/s, where the
// steady state at low friction lies past the fold of the branch from straight
// running. Each variation's steady state is solved on that branch (the
// steady_state analysis's default start, solveFromStraightRunning), so a row
// is either that state or the named "no steady state on the branch from
// straight running: fold at front steer X deg"; the rows are the same on 1
// and 2 threads. Independent check, per point: a transient from straight
// running whose front and rear angles ramp slowly (the `ramp` command, 0.5
// deg/s front, the rear in proportion) to the same angles settles to the
// reported yaw rate within 1e-6 (relative), or, where the point is past the
// fold, spins out (a spin_out event, made fatal to end the run).
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <string>

#include "test_util.h"
#include "vdyn/core/named_outcome.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180;
constexpr double kSpeed = 15.0;  // m/s
const std::string kFoldHead = "no steady state on the branch from straight running: fold at front steer ";

std::vector<Override> toOverrides(const std::vector<SweepSetting>& settings) {
  std::vector<Override> o;
  for (const auto& s : settings) o.push_back(Override{s.key, s.value});
  return o;
}

RunOptions noFiles() {
  RunOptions ro;
  ro.plots = false;
  return ro;
}

std::vector<Override> at15() {
  return {{"vehicle.initial_speed_m_s", kSpeed}, {"plugins.speed_hold.speed_m_s", kSpeed}};
}

/// The ch3 transient from straight running with the front angle ramped at
/// `rateDegS` to 4 deg and the rear in proportion to 1 deg (both ramps end
/// together), then held until t_end_s; spin_out ends the run with an Error.
SceneDescription rampTransient(const Variation& v, double rateDegS, double tEnd) {
  const SceneDescription base = SceneDescription::fromFile("scenes/ch3_transient.json", standardRegistry());
  const double blend = 0.5;  // s
  auto ramp = [&](double finalDeg, double rate) {
    return Json{{"type", "ramp"},        {"initial_rad", 0.0}, {"final_rad", finalDeg * kDeg},
                {"rate_rad_s", rate * kDeg}, {"start_time_s", 0.5}, {"blend_s", blend}};
  };
  std::vector<Override> o = at15();
  for (const auto& x : toOverrides(v.settings)) o.push_back(x);
  o.push_back({"plugins.front_steer.command", ramp(4.0, rateDegS)});
  o.push_back({"plugins.rear_steer.command", ramp(1.0, rateDegS / 4)});
  o.push_back({"analysis.t_end_s", tEnd});
  o.push_back({"analysis.events.fatal", Json::array({"spin_out"})});
  return base.withOverrides(o);
}

}  // namespace

TEST(LimitSweep, EveryPointIsOnTheBranchFromStraightRunningOrPastTheFoldAsARampSteerShows) {
  // mu_max 0.5 (past the fold at 15 m/s) and 0.9 (a steady turn) at both
  // ends of the rear spring range, App. A's front spring (9.16e4 N/m).
  const SweepDescription d = SweepDescription::fromJson(Json::parse(R"({
    "scene": "scenes/ch3_steady_state.json",
    "set": {"vehicle.initial_speed_m_s": 15.0, "plugins.speed_hold.speed_m_s": 15.0},
    "variations": [{"grid": [
      {"keys": ["vehicle.overrides.tire.params.mu_max", "vehicle.overrides.tire.params.mu_min"],
       "values": [[0.5, 0.375], [0.9, 0.675]]},
      {"key": "vehicle.overrides.axles.rear.suspension.spring.stiffness_N_per_m", "values": [4.58e4, 1.832e5]}
    ]}],
    "collect": ["steady.chassis.yaw_rate_rad_s", "least_damped_eigenvalue[0]"]
  })"),
                                                        "limit_sweep:", "");
  const SceneDescription base =
      SceneDescription::fromFile("scenes/ch3_steady_state.json", standardRegistry(), toOverrides(d.common));
  const SweepRunFunction run = [&](const SweepDescription&, const Variation& v) {
    return runScene(base.withOverrides(toOverrides(v.settings)), noFiles());
  };
  SweepOptions o1, o2;
  o2.threads = 2;
  const SweepResult r1 = runSweep(d, run, o1), r2 = runSweep(d, run, o2);
  EXPECT_EQ(formatSweepCsv(d, r1.rows), formatSweepCsv(d, r2.rows));
  int ok = 0, past = 0;
  for (const SweepRow& row : r1.rows) {
    const Variation& v = d.variations[row.index];
    std::printf("variation %zu (%s): %s\n", row.index, v.id().c_str(),
                row.ok ? ("yaw rate " + formatValue(row.values[0].get<double>()) + " rad/s, least-damped "
                          "eigenvalue real part " + formatValue(row.values[1].get<double>()) + " 1/s")
                             .c_str()
                       : row.reason.c_str());
    if (row.ok) {
      ++ok;
      const double r = row.values[0].get<double>(), sigma = row.values[1].get<double>();
      EXPECT_GT(r, 0) << "a left steer turns left on the branch from straight running";
      ASSERT_LT(sigma, 0) << "a steady state on the branch before the fold is stable";
      // Ramp end 0.5 + 8 + 0.5 s, then 20 time constants of the least-damped mode.
      const double tEnd = 9.0 + 20.0 / -sigma;
      const Json s = runScene(rampTransient(v, 0.5, tEnd), noFiles());
      const double rt = s.at("final").at("chassis.yaw_rate_rad_s").get<double>();
      std::printf("  ramp steer transient to %.1f s: yaw rate %.12g rad/s (relative difference %.1e)\n", tEnd, rt,
                  (rt - r) / r);
      EXPECT_NEAR(rt, r, 1e-6 * r);
      EXPECT_TRUE(s.at("events").empty()) << s.at("events").dump();
    } else {
      ++past;
      ASSERT_EQ(row.reason.rfind(kFoldHead, 0), 0u) << row.reason;
      const double foldDeg = std::stod(row.reason.substr(kFoldHead.size()));
      EXPECT_GT(foldDeg, 0);
      EXPECT_LT(foldDeg, 4.0);
      const std::string e = errorOf([&] { runScene(rampTransient(v, 0.5, 40.0), noFiles()); });
      std::printf("  ramp steer transient: %s\n", e.c_str());
      EXPECT_NE(e.find("spin_out at t = "), std::string::npos) << e;
    }
  }
  EXPECT_GE(ok, 1);
  EXPECT_GE(past, 1);
}

namespace {

std::vector<std::vector<double>> readCsvColumns(const std::string& path, const std::vector<std::string>& names) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  std::vector<std::string> head;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) head.push_back(c);
  }
  std::vector<std::size_t> idx;
  for (const auto& n : names) {
    const auto it = std::find(head.begin(), head.end(), n);
    if (it == head.end()) throw Error(path + ": no column " + n);
    idx.push_back(std::size_t(it - head.begin()));
  }
  std::vector<std::vector<double>> cols(names.size());
  while (std::getline(f, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) row.push_back(std::stod(c));
    for (std::size_t k = 0; k < idx.size(); ++k) cols[k].push_back(row.at(idx[k]));
  }
  return cols;
}

double numberAfter(const std::string& text, const std::string& head) {
  const auto p = text.find(head);
  if (p == std::string::npos) throw Error("no '" + head + "' in: " + text);
  return std::stod(text.substr(p + head.size()));
}

}  // namespace

// The ch3 turn's limit (front and rear angles in the ratio 4:1, App. A's
// tires) as the fold of the branch from straight running, against a slow
// ramp-steer transient (front 0.1 deg/s, rear 0.025 deg/s). The fold is a
// saddle-node: a slowly ramped vehicle follows the stable branch, passes
// through the fold's state and leaves along the branch's direction there
// (the unstable branch), later spinning out. The transient's lateral
// acceleration along its path, U (r + d beta / dt), where its side slip
// passes the fold's side slip (the departure) is the fold's lateral
// acceleration r U within 2 % (measured: +0.58 % at 10 m/s, +0.93 % at 15
// m/s). The command has then passed the fold's angle by 0.34 deg (10 m/s)
// and 0.26 deg (15 m/s): the delay of a ramped passage through a
// saddle-node, which grows with the ramp rate; r U when the command passes
// the fold's angle is 9 % below the fold's at 15 m/s (a_y(delta) is vertical
// at a fold), and the spin_out event comes 5-10 s after the departure.
TEST(LimitSweep, FoldInFrontSteerAgreesWithTheSlowRampSteerDeparture) {
  const SceneDescription steady = SceneDescription::fromFile("scenes/ch3_steady_state.json", standardRegistry());
  const SceneDescription transient = SceneDescription::fromFile("scenes/ch3_transient.json", standardRegistry());
  for (const double U : {10.0, 15.0}) {
    const std::vector<Override> speed = {{"vehicle.initial_speed_m_s", U}, {"plugins.speed_hold.speed_m_s", U}};
    // The fold: the homotopy from straight running towards 30 deg / 7.5 deg.
    SceneDescription big = steady.withOverrides(speed).withOverrides(
        {{"plugins.front_steer.command.final_rad", 30 * kDeg}, {"plugins.rear_steer.command.final_rad", 7.5 * kDeg}});
    const std::string msg = errorOf([&] { runScene(big, noFiles()); });
    ASSERT_EQ(msg.rfind(kFoldHead, 0), 0u) << msg;
    const double foldDeg = numberAfter(msg, kFoldHead), foldAy = numberAfter(msg, "(lateral acceleration ");
    const double foldTime = numberAfter(msg, "at command time ");
    // The fold's side slip: the branch's state 2e-6 s of command time before
    // it (the fold is located to 1.5e-7 s; beta goes as the square root of
    // the distance to the fold: within about 1e-3 rad of the fold's, which
    // moves the departure by about 0.02 s).
    const Json nearFold = runScene(big.withOverride("analysis.time_s", foldTime - 2e-6), noFiles());
    const double foldBeta = nearFold.at("steady").at("chassis.side_slip_rad").get<double>();
    EXPECT_NEAR(nearFold.at("steady").at("chassis.yaw_rate_rad_s").get<double>() * U, foldAy, 0.01 * foldAy);

    // The ramp: front 0.1 deg/s to 30 deg, rear 0.025 deg/s, until the spin.
    const double rate = 0.1;  // deg/s
    auto ramp = [&](double finalDeg, double r) {
      return Json{{"type", "ramp"},     {"initial_rad", 0.0}, {"final_rad", finalDeg * kDeg},
                  {"rate_rad_s", r * kDeg}, {"start_time_s", 0.5}, {"blend_s", 0.5}};
    };
    const std::string dir = std::filesystem::temp_directory_path().string() + "/vdyn_test_limit_ramp_" +
                            std::to_string(int(U)) + "_" + std::to_string(::getpid());
    RunOptions ro = noFiles();
    ro.out_dir = dir;
    const double tEnd = 0.5 + foldDeg / rate + 20;  // the spin comes within 20 s past the fold's angle
    const Json s = runScene(transient.withOverrides(speed).withOverrides(
                                {{"plugins.front_steer.command", ramp(30, rate)},
                                 {"plugins.rear_steer.command", ramp(7.5, rate / 4)},
                                 {"analysis.t_end_s", tEnd},
                                 {"analysis.report_interval_s", 0.05}}),
                            ro);
    ASSERT_FALSE(s.at("events").empty()) << "no spin_out by " << tEnd << " s at " << U << " m/s";
    EXPECT_EQ(s.at("events")[0].at("kind"), "spin_out");
    const auto c = readCsvColumns(dir + "/history.csv",
                                  {"t_s", "chassis.yaw_rate_rad_s", "chassis.side_slip_rad", "front_steer.command_rad"});
    std::filesystem::remove_all(dir);
    const auto &t = c[0], &r = c[1], &b = c[2], &d = c[3];
    // From where the command reaches the fold's angle (the side slip has not
    // yet reached the fold's there: the passage lags), the first report
    // interval where beta passes the fold's beta, interpolated linearly.
    std::size_t i = 1;
    while (i + 1 < t.size() && d[i] < foldDeg * kDeg) ++i;
    const double sgn = foldBeta - b[i] > 0 ? 1 : -1;
    while (i + 2 < t.size() && sgn * (foldBeta - b[i + 1]) > 0) ++i;
    ASSERT_LT(i + 2, t.size()) << "the transient's side slip never reaches the fold's";
    auto pathAy = [&](std::size_t k) { return U * (r[k] + (b[k + 1] - b[k - 1]) / (t[k + 1] - t[k - 1])); };
    const double w = (foldBeta - b[i]) / (b[i + 1] - b[i]);
    const double ay = pathAy(i) + w * (pathAy(i + 1) - pathAy(i));
    const double dDeg = (d[i] + w * (d[i + 1] - d[i])) / kDeg, tDep = t[i] + w * (t[i + 1] - t[i]);
    std::printf("%g m/s: fold at front steer %.4f deg, a_y %.4f m/s^2, side slip %.5f rad; ramp %.1f deg/s departs "
                "at t = %.2f s (command %.4f deg): path a_y %.4f m/s^2 (%+.2f %%); %s\n",
                U, foldDeg, foldAy, foldBeta, rate, tDep, dDeg, ay, 100 * (ay - foldAy) / foldAy,
                s.at("events")[0].at("message").get<std::string>().c_str());
    EXPECT_NEAR(ay, foldAy, 0.02 * foldAy);
    EXPECT_LT(dDeg - foldDeg, 1.0);  // the passage's delay, command angle past the fold's (deg)
    EXPECT_GT(s.at("events")[0].at("time_s").get<double>(), tDep);
  }
}

// A wheel lift-off on the branch from straight running (issue 24: the
// homotopy's quasi-Newton corrector crosses the contact's kink that Newton
// stalled at, into states with the inner front wheel hanging and its spin
// free). Two rows of the 15 m/s design sweep with soft rear springs (4.58e4
// N/m), mu_max 0.7: with the stiffest-but-one front springs (1.5572e5 N/m)
// the branch's first point past the kink has the inner front tire unloaded
// (0 N) at front steer 3.4836 deg, before the asked 4 deg; with 1.2824e5 N/m
// the branch folds back exactly at the kink (3.5627 deg, the tire's load
// there ~1e-4 N of 1923 N): both are the named outcome past_lift_off, not a
// fold and not a failed run.
TEST(LimitSweep, AWheelLiftOffOnTheBranchIsNamedWhereItHappens) {
  auto outcomeOf = [](double frontSpring) {
    std::vector<Override> o = at15();
    o.push_back({"vehicle.overrides.tire.params.mu_max", 0.7});
    o.push_back({"vehicle.overrides.tire.params.mu_min", 0.525});
    o.push_back({"vehicle.overrides.axles.rear.suspension.spring.stiffness_N_per_m", 4.58e4});
    o.push_back({"vehicle.overrides.axles.front.suspension.spring.stiffness_N_per_m", frontSpring});
    try {
      runScene(SceneDescription::fromFile("scenes/ch3_steady_state.json", standardRegistry(), o), noFiles());
    } catch (const NamedOutcome& e) {
      std::printf("front spring %g N/m: %s: %s\n", frontSpring, e.status().c_str(), e.what());
      return std::make_pair(e.status(), std::string(e.what()));
    }
    return std::make_pair(std::string("ok"), std::string());
  };
  const std::string head = "no steady state found on the branch from straight running past a wheel lift-off: ";
  {
    const auto [status, msg] = outcomeOf(1.5572e5);
    EXPECT_EQ(status, "past_lift_off");
    EXPECT_EQ(msg.rfind(head + "tire_lf.Fz_N = 0 N (", 0), 0u) << msg;
    EXPECT_NEAR(numberAfter(msg, "at front steer "), 3.4836, 1e-3) << msg;
    EXPECT_NE(msg.find("the first point of the branch past the contact's kink"), std::string::npos) << msg;
  }
  {
    const auto [status, msg] = outcomeOf(1.2824e5);
    EXPECT_EQ(status, "past_lift_off");
    EXPECT_EQ(msg.rfind(head + "tire_lf.Fz_N = ", 0), 0u) << msg;
    EXPECT_LT(numberAfter(msg, "tire_lf.Fz_N = "), 1e-2) << msg;  // N, of 1923 N at straight running
    EXPECT_NEAR(numberAfter(msg, "at front steer "), 3.5627, 1e-3) << msg;
    EXPECT_NE(msg.find("a fold of the branch where the wheel lifts off"), std::string::npos) << msg;
  }
}
