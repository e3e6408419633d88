// handling: the standard handling tests by name (plugins/handling) on the
// App. A 4WS vehicle (rear-steer strategies 2ws, linear, nonlinear) and the
// nonlinear bicycle: ISO 4138 constant radius (steady-state solves continued in
// speed), ISO 7401 step steer and frequency response (linearisation, checked
// against sine-steer simulations), FMVSS 126 sine with dwell. CSV per run,
// PNG plots, summary.json, printed tables and the 2WS/4WS ranking.
#include "vdyn/core/text.h"
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "study.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/handling/iso4138.h"
#include "vdyn/handling/iso7401.h"
#include "vdyn/handling/sine_with_dwell.h"
#include "vdyn/vehicles/handling_vehicles.h"

using namespace vdyn;

namespace {
const double kDeg = SimTK::Pi / 180;

/// `digits` significant digits, `missing` for a value that is not there (non-finite).
std::string sig(double v, int digits = 4, const char* missing = "-") {
  return std::isfinite(v) ? formatSig(v, digits) : missing;
}

struct Config {
  ParamReader data;
  std::string fourws_data, bicycle_data;  ///< vehicle data files
  HandlingSetup setup;                    ///< kr_table, linear_bicycle, tire_width_m (rear_strategy per vehicle)
};

/// The vehicle ("bicycle" or "4ws/<strategy>") as a scene (the vehicle from
/// its data file, no plugins) prepared for the handling tests: the one
/// composition path of the scene files' handling analyses.
std::unique_ptr<HandlingScene> build(const Config& c, const std::string& vehicle) {
  const bool bike = vehicle == "bicycle";
  HandlingSetup setup = c.setup;
  if (!bike) setup.rear_strategy = vehicle.substr(4);  // "4ws/<strategy>"
  const Json scene = {{"name", "handling"},
                      {"vehicle", {{"type", bike ? "bicycle" : "fourws"}, {"data", bike ? c.bicycle_data : c.fourws_data}}},
                      {"analysis", {{"type", "iso4138_constant_radius"}}}};
  return buildHandlingScene(SceneDescription::fromJson(scene, "", standardRegistry()), setup);
}

std::string fileTag(const std::string& vehicle) {
  std::string t = vehicle;
  for (char& ch : t)
    if (ch == '/') ch = '_';
  return t;
}

/// ISO 4138 at one radius (one job).
ConstantRadiusResult runIso4138(const Config& c, const std::string& vehicle, double R) {
  auto b = build(c, vehicle);
  ConstantRadiusSettings set = ConstantRadiusSettings::fromParams(c.data.child("iso4138"));
  set.radius_m = R;
  return runConstantRadius(b->vehicle, set);
}

/// ISO 4138's files, summary and lines from the radii's results (in radii_m order).
Json iso4138(const Config& c, const std::string& vehicle, const std::vector<ConstantRadiusResult>& results,
             const std::string& out, bool plots) {
  Json j = Json::array();
  const ParamReader p = c.data.child("iso4138");
  std::vector<study::Series> sd, sb, sr, sk, hd;
  const std::vector<double> radii = p.numbers("radii_m");
  for (std::size_t ri = 0; ri < radii.size(); ++ri) {
    const double R = radii[ri];
    const ConstantRadiusResult& r = results.at(ri);
    const std::string csv = out + "/iso4138_" + fileTag(vehicle) + "_R" + formatValue(R) + ".csv";
    OutputFile f(csv);
    f << "speed_m_s,lateral_accel_m_s2,front_deg,rear_deg,side_slip_deg,roll_deg,yaw_rate_rad_s,"
         "understeer_gradient_deg_per_m_s2,delta_minus_l_over_R_deg,stable,least_damped_re_per_s,least_damped_im_per_s,"
         "iterations\n";
    f.precision(10);
    Json pts = Json::array();
    for (const auto& q : r.points) {
      f << q.speed_m_s << ',' << q.lateral_accel_m_s2 << ',' << q.front_rad / kDeg << ',' << q.rear_rad / kDeg << ','
        << q.side_slip_rad / kDeg << ',' << q.roll_rad / kDeg << ',' << q.yaw_rate_rad_s << ','
        << q.understeer_gradient_rad_per_m_s2 / kDeg << ',' << (q.front_rad - r.wheelbase_m / R) / kDeg << ','
        << int(q.stable) << ',' << q.least_damped.real() << ',' << q.least_damped.imag() << ',' << q.iterations << '\n';
    }
    f.commit();
    auto usAt = [&](double ay) {
      // Understeer gradient at a lateral acceleration (linear interpolation along the sweep).
      std::vector<double> x, y;
      for (const auto& q : r.points) x.push_back(q.lateral_accel_m_s2), y.push_back(q.understeer_gradient_rad_per_m_s2);
      return ay <= r.limit_lateral_accel_m_s2 ? interpolate(x, y, ay) / kDeg : std::nan("");
    };
    Json jr = {{"radius_m", R},
               {"points", r.points.size()},
               {"limit_found", r.limit_found},
               {"limit_speed_m_s", r.limit_speed_m_s},
               {"limit_lateral_accel_m_s2", r.limit_lateral_accel_m_s2},
               {"understeer_gradient_linear_deg_per_m_s2", r.understeer_gradient_linear_rad_per_m_s2 / kDeg},
               {"understeer_gradient_at_2_m_s2_deg_per_m_s2", usAt(2)},
               {"understeer_gradient_at_4_m_s2_deg_per_m_s2", usAt(4)},
               {"understeer_gradient_at_6_m_s2_deg_per_m_s2", usAt(6)},
               {"stability_lost_speed_m_s", r.stability_lost_speed_m_s},
               {"stability_lost_lateral_accel_m_s2", r.stability_lost_lateral_accel_m_s2},
               {"solve_wall_time_s", r.solve_wall_time_s},
               {"stability_wall_time_s", r.stability_wall_time_s},
               {"wall_time_s", r.wall_time_s},
               {"residual_evaluations", r.residual_evaluations},
               {"csv", csv}};
    if (!std::isfinite(r.stability_lost_speed_m_s)) jr["stability_lost_speed_m_s"] = nullptr, jr["stability_lost_lateral_accel_m_s2"] = nullptr;
    for (const char* k : {"understeer_gradient_at_2_m_s2_deg_per_m_s2", "understeer_gradient_at_4_m_s2_deg_per_m_s2",
                          "understeer_gradient_at_6_m_s2_deg_per_m_s2"})
      if (!std::isfinite(jr[k].get<double>())) jr[k] = nullptr;
    j.push_back(jr);
    std::printf("  ISO 4138 %-14s R %g m: %zu points, limit a_y %s m/s^2 at %s m/s%s, K(0) %s deg/(m/s^2), "
                "stability lost %s, %s s (solves %s s)\n",
                vehicle.c_str(), R, r.points.size(), sig(r.limit_lateral_accel_m_s2).c_str(),
                sig(r.limit_speed_m_s).c_str(), r.limit_found ? "" : " (speed_max)",
                sig(r.understeer_gradient_linear_rad_per_m_s2 / kDeg).c_str(),
                std::isfinite(r.stability_lost_lateral_accel_m_s2)
                    ? ("at " + sig(r.stability_lost_lateral_accel_m_s2) + " m/s^2").c_str()
                    : "never",
                sig(r.wall_time_s, 3).c_str(), sig(r.solve_wall_time_s, 3).c_str());
    const std::string lab = "R " + formatValue(R) + " m";
    sd.push_back({csv, "lateral_accel_m_s2", "front_deg", lab});
    sb.push_back({csv, "lateral_accel_m_s2", "side_slip_deg", lab});
    sr.push_back({csv, "lateral_accel_m_s2", "roll_deg", lab});
    sk.push_back({csv, "lateral_accel_m_s2", "understeer_gradient_deg_per_m_s2", lab});
    hd.push_back({csv, "delta_minus_l_over_R_deg", "lateral_accel_m_s2", lab});
  }
  if (plots) {
    const std::string t = fileTag(vehicle);
    study::plot({{out + "/iso4138_" + t + "_steer.png", "ISO 4138 " + vehicle + ": front steering angle", "a_y (m/s^2)",
                  "delta_f (deg)", sd, false, false, false, true},
                 {out + "/iso4138_" + t + "_side_slip.png", "ISO 4138 " + vehicle + ": side slip", "a_y (m/s^2)",
                  "beta (deg)", sb, false, false, false, true},
                 {out + "/iso4138_" + t + "_roll.png", "ISO 4138 " + vehicle + ": roll angle", "a_y (m/s^2)",
                  "roll (deg)", sr, false, false, false, true},
                 {out + "/iso4138_" + t + "_understeer.png", "ISO 4138 " + vehicle + ": understeer gradient",
                  "a_y (m/s^2)", "d delta_f / d a_y (deg/(m/s^2))", sk, false, false, false, true},
                 {out + "/iso4138_" + t + "_handling_diagram.png", "handling diagram " + vehicle,
                  "delta_f - l/R (deg)", "a_y (m/s^2)", hd, false, false, false, true}});
  }
  return j;
}

/// ISO 7401's step steer and linear frequency response (one job), the
/// response at 1 Hz (from the sweep if it holds 1 Hz).
struct Iso7401Run {
  StepSteerResult step;
  FrequencyResponseResult fr;
  FrequencyResponsePoint at1;
};
Iso7401Run runIso7401(const Config& c, const std::string& vehicle) {
  const ParamReader p = c.data.child("iso7401");
  auto b = build(c, vehicle);
  const StepSteerSettings set = StepSteerSettings::fromParams(p);
  Iso7401Run r;
  r.step = runStepSteer(b->vehicle, set);
  r.fr = calcSteeringFrequencyResponse(
      b->vehicle, set.speed_m_s,
      logFrequencies(p.number("frequency_from_Hz"), p.number("frequency_to_Hz"), p.integer("frequency_count")));
  bool have = false;
  for (const auto& q : r.fr.points)
    if (!have && std::abs(q.frequency_Hz - 1.0) < 1e-9) r.at1 = q, have = true;
  if (!have) r.at1 = calcSteeringFrequencyResponse(b->vehicle, set.speed_m_s, {1.0}).points.at(0);
  return r;
}

/// ISO 7401's check at one frequency (one job): the sine-steer simulation and the linear response.
struct SineCheck {
  SineSteerResult sim;
  FrequencyResponsePoint lin;
};
SineCheck runSineCheck(const Config& c, const std::string& vehicle, double f) {
  const ParamReader p = c.data.child("iso7401");
  auto b = build(c, vehicle);
  const StepSteerSettings set = StepSteerSettings::fromParams(p);
  SineCheck k;
  k.sim = runSineSteer(b->vehicle, set.speed_m_s, f, p.number("check_amplitude_rad"), set.integrator);
  k.lin = calcSteeringFrequencyResponse(b->vehicle, set.speed_m_s, {f}).points.at(0);
  return k;
}

Json iso7401(const Config& c, const std::string& vehicle, const Iso7401Run& run, const std::vector<SineCheck>& checks,
             const std::string& out, bool plots, bool check) {
  const ParamReader p = c.data.child("iso7401");
  const StepSteerSettings set = StepSteerSettings::fromParams(p);
  const StepSteerResult& st = run.step;
  const std::string t = fileTag(vehicle);
  const std::string stepCsv = out + "/iso7401_step_" + t + ".csv";
  st.history.writeCsv(stepCsv);
  const FrequencyResponseResult& fr = run.fr;
  const std::string frCsv = out + "/iso7401_frequency_" + t + ".csv";
  {
    OutputFile f(frCsv);
    f.precision(10);
    f << "frequency_Hz,yaw_gain_1_per_s,yaw_phase_deg,ay_gain_m_s2_per_rad,ay_phase_deg\n";
    for (const auto& q : fr.points)
      f << q.frequency_Hz << ',' << q.yaw_gain_1_per_s << ',' << q.yaw_phase_deg << ',' << q.ay_gain_m_s2_per_rad
        << ',' << q.ay_phase_deg << '\n';
    f.commit();
  }
  Json j = {{"speed_m_s", set.speed_m_s},
            {"front_deg", st.front_rad / kDeg},
            {"rear_deg", st.rear_rad / kDeg},
            {"steady_yaw_rate_rad_s", st.steady_yaw_rate_rad_s},
            {"steady_lateral_accel_m_s2", st.steady_lateral_accel_m_s2},
            {"yaw_rate_gain_1_per_s", st.yaw_rate_gain_1_per_s},
            {"yaw_response_time_s", st.yaw_response_time_s},
            {"yaw_peak_response_time_s", std::isfinite(st.yaw_peak_response_time_s) ? Json(st.yaw_peak_response_time_s) : Json(nullptr)},
            {"yaw_overshoot", st.yaw_overshoot},
            {"lateral_accel_response_time_s", st.lateral_accel_response_time_s},
            {"lateral_accel_peak_response_time_s", std::isfinite(st.lateral_accel_peak_response_time_s) ? Json(st.lateral_accel_peak_response_time_s) : Json(nullptr)},
            {"lateral_accel_overshoot", st.lateral_accel_overshoot},
            {"final_yaw_rate_rel_diff", std::abs(st.final_yaw_rate_rad_s / st.steady_yaw_rate_rad_s - 1)},
            {"step_steps", st.run.steps},
            {"frequency_response_dimension", fr.dimension},
            {"frequency_response_wall_time_s", fr.wall_time_s},
            {"linear_yaw_gain_zero_1_per_s", fr.yaw_gain_zero_1_per_s},
            {"step_csv", stepCsv},
            {"frequency_csv", frCsv}};
  // Yaw gain -3 dB bandwidth proxy: the frequency of the largest yaw gain.
  double fPeak = 0, gPeak = 0;
  for (const auto& q : fr.points)
    if (q.yaw_gain_1_per_s > gPeak) gPeak = q.yaw_gain_1_per_s, fPeak = q.frequency_Hz;
  j["yaw_gain_peak_frequency_Hz"] = fPeak;
  j["yaw_gain_peak_over_steady"] = gPeak / fr.yaw_gain_zero_1_per_s;
  const FrequencyResponsePoint& at1 = run.at1;
  j["yaw_phase_at_1Hz_deg"] = at1.yaw_phase_deg;
  j["ay_phase_at_1Hz_deg"] = at1.ay_phase_deg;
  std::printf("  ISO 7401 %-14s step to %s deg: r/delta %s 1/s, response time %s s, peak response time %s, overshoot "
              "%s %%; a_y response time %s s; FR: yaw phase at 1 Hz %s deg, a_y phase %s deg, peak gain x%s at %s Hz\n",
              vehicle.c_str(), sig(st.front_rad / kDeg).c_str(), sig(st.yaw_rate_gain_1_per_s).c_str(),
              sig(st.yaw_response_time_s, 3).c_str(),
              std::isfinite(st.yaw_peak_response_time_s) ? (sig(st.yaw_peak_response_time_s, 3) + " s").c_str()
                                                         : "- (no peak: monotone rise)",
              sig(100 * st.yaw_overshoot, 3).c_str(), sig(st.lateral_accel_response_time_s, 3).c_str(),
              sig(at1.yaw_phase_deg, 3).c_str(), sig(at1.ay_phase_deg, 3).c_str(),
              sig(gPeak / fr.yaw_gain_zero_1_per_s, 3).c_str(), sig(fPeak, 3).c_str());
  if (check) {
    Json cj = Json::array();
    const std::vector<double> freqs = p.numbers("check_frequencies_Hz");
    for (std::size_t fi = 0; fi < freqs.size(); ++fi) {
      const double f = freqs[fi];
      const SineSteerResult& s = checks.at(fi).sim;
      const FrequencyResponsePoint& l = checks.at(fi).lin;
      auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
      cj.push_back({{"frequency_Hz", f},
                    {"sim_yaw_gain", s.yaw_gain_1_per_s},
                    {"lin_yaw_gain", l.yaw_gain_1_per_s},
                    {"sim_yaw_phase_deg", s.yaw_phase_deg},
                    {"lin_yaw_phase_deg", l.yaw_phase_deg},
                    {"sim_ay_gain", s.ay_gain_m_s2_per_rad},
                    {"lin_ay_gain", l.ay_gain_m_s2_per_rad},
                    {"sim_ay_phase_deg", s.ay_phase_deg},
                    {"lin_ay_phase_deg", l.ay_phase_deg},
                    {"yaw_gain_rel_diff", rel(s.yaw_gain_1_per_s, l.yaw_gain_1_per_s)},
                    {"ay_gain_rel_diff", rel(s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad)},
                    {"sim_wall_time_s", s.run.wall_time_s}});
      std::printf("    sine %.2f Hz: yaw gain sim %.5f lin %.5f (%.2e), phase sim %.3f lin %.3f deg; a_y gain sim %.4f lin "
                  "%.4f (%.2e), phase sim %.3f lin %.3f deg\n",
                  f, s.yaw_gain_1_per_s, l.yaw_gain_1_per_s, rel(s.yaw_gain_1_per_s, l.yaw_gain_1_per_s), s.yaw_phase_deg,
                  l.yaw_phase_deg, s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad,
                  rel(s.ay_gain_m_s2_per_rad, l.ay_gain_m_s2_per_rad), s.ay_phase_deg, l.ay_phase_deg);
    }
    j["sine_check"] = cj;
  }
  if (plots) {
    study::plot({{out + "/iso7401_step_" + t + ".png", "ISO 7401 step steer " + vehicle, "t (s)", "yaw rate (rad/s)",
                  {{stepCsv, "t_s", "yaw_rate_rad_s", "yaw rate"}}},
                 {out + "/iso7401_step_ay_" + t + ".png", "ISO 7401 step steer " + vehicle, "t (s)", "a_y (m/s^2)",
                  {{stepCsv, "t_s", "lateral_accel_m_s2", "lateral acceleration"}}},
                 {out + "/iso7401_gain_" + t + ".png", "ISO 7401 frequency response " + vehicle + ": yaw-rate gain",
                  "f (Hz)", "yaw-rate gain r / delta (1/s)", {{frCsv, "frequency_Hz", "yaw_gain_1_per_s", "yaw rate (1/s)"}}, false, true, false, true},
                 {out + "/iso7401_phase_" + t + ".png", "ISO 7401 frequency response " + vehicle, "f (Hz)", "phase (deg)",
                  {{frCsv, "frequency_Hz", "yaw_phase_deg", "yaw rate"}, {frCsv, "frequency_Hz", "ay_phase_deg", "a_y"}},
                  false, true, false, true}});
  }
  return j;
}

Json sineWithDwell(const Config& c, const std::string& vehicle, const SineWithDwellResult& r, const std::string& out,
                   bool plots) {
  const SineWithDwellSettings set = SineWithDwellSettings::fromParams(c.data.child("sine_with_dwell"));
  const std::string t = fileTag(vehicle);
  Json runs = Json::array();
  std::vector<study::Series> ser;
  // Ratios and displacement over the completed runs only; a spun-out or failed
  // run has no number: it is counted, and the first one named.
  double worst1 = -1e300, worst175 = -1e300, minDisp = 1e300;
  int spun = 0, failed = 0, completedFrom5 = 0;
  std::string firstFail;  // the smallest amplitude that fails, and why
  double firstFailFactor = std::nan("");
  for (const auto& run : r.runs) {
    Json jr = {{"factor", run.factor}, {"amplitude_deg", run.amplitude_rad / kDeg}, {"completed", run.completed},
               {"spun_out", run.spun_out}, {"pass", run.pass}};
    if (run.completed) {
      const std::string csv = out + "/swd_" + t + "_" + formatValue(run.factor) + "A.csv";
      run.history.writeCsv(csv);
      ser.push_back({csv, "t_s", "yaw_rate_rad_s", formatValue(run.factor) + " A"});
      jr["peak_yaw_rate_rad_s"] = run.peak_yaw_rate_rad_s;
      jr["peak_time_s"] = run.peak_time_s;
      jr["yaw_ratio_1s"] = run.yaw_ratio_1s;
      jr["yaw_ratio_1_75s"] = run.yaw_ratio_175;
      jr["lateral_displacement_m"] = run.lateral_displacement_m;
      worst1 = std::max(worst1, run.yaw_ratio_1s);
      worst175 = std::max(worst175, run.yaw_ratio_175);
      if (run.factor >= set.displacement_from_factor - 1e-9) {
        minDisp = std::min(minDisp, run.lateral_displacement_m);
        ++completedFrom5;
      }
    } else {
      jr["reason"] = run.reason;
      ++(run.spun_out ? spun : failed);
    }
    if (!run.pass && firstFail.empty()) firstFailFactor = run.factor;
    if (!run.pass && firstFail.empty())
      firstFail = (run.spun_out ? "spin" : !run.completed ? "failed" : run.yaw_ratio_1s > set.yaw_ratio_1s_limit ? "r1.0"
                   : run.yaw_ratio_175 > set.yaw_ratio_175_limit ? "r1.75" : "disp") + std::string(" ") +
                  formatValue(run.factor) + "A";
    runs.push_back(jr);
  }
  const int completed = int(r.runs.size()) - spun - failed;
  std::printf("  SWD      %-14s A %.3f deg, %zu runs: %d completed, %d spun out, %d failed; completed runs: max ratio "
              "1.0 s %s, 1.75 s %s; displacement from %g A %s -> %s%s\n",
              vehicle.c_str(), r.angle_A_rad / kDeg, r.runs.size(), completed, spun, failed,
              completed ? sig(worst1, 3).c_str() : "-", completed ? sig(worst175, 3).c_str() : "-",
              set.displacement_from_factor,
              completedFrom5 ? ("min " + sig(minDisp, 3) + " m").c_str() : "(no run completed)",
              r.pass ? "PASS" : "FAIL", firstFail.empty() ? "" : (" (first: " + firstFail + ")").c_str());
  if (plots && !ser.empty())
    study::plot({{out + "/swd_" + t + ".png", "sine with dwell " + vehicle, "t (s)", "yaw rate (rad/s)", ser}});
  auto orNull = [](bool have, double x) { return have ? Json(x) : Json(nullptr); };
  return {{"angle_A_deg", r.angle_A_rad / kDeg},
          {"runs", runs},
          {"pass", r.pass},
          {"completed_runs", completed},
          {"spun_out_runs", spun},
          {"failed_runs", failed},
          {"first_fail", firstFail.empty() ? Json(nullptr) : Json(firstFail)},
          {"first_fail_factor", orNull(!firstFail.empty(), firstFailFactor)},
          {"max_yaw_ratio_1s", orNull(completed > 0, worst1)},
          {"max_yaw_ratio_1_75s", orNull(completed > 0, worst175)},
          {"min_lateral_displacement_m", orNull(completedFrom5 > 0, minDisp)}};
}
/// ISO 3888-2 (one job: its search's rounds are sequential): the scene run as
/// `vdyn run` does (its files in <out>/iso3888_<vehicle>/); its summary, and
/// the integrator steps of its runs.
struct Iso3888Job {
  Json summary;
  long steps = 0;
};
Iso3888Job runIso3888Scene(const Config& c, const std::string& vehicle, const std::string& out, bool plots) {
  const ParamReader p = c.data.child("iso3888");
  const bool bike = vehicle == "bicycle";
  std::vector<Override> ov;
  if (!bike) ov.push_back({"plugins.rear_control.strategy", vehicle.substr(4)});
  const SceneDescription scene =
      SceneDescription::fromFile(p.string(bike ? "scene_bicycle" : "scene_fourws"), standardRegistry(), ov);
  RunOptions opt;
  opt.out_dir = out + "/iso3888_" + fileTag(vehicle);
  opt.plots = plots;
  const SceneRun run = runSceneWithTables(scene, opt);
  Iso3888Job j;
  j.summary = run.summary;
  for (const auto& [name, table] : run.tables) {
    if (name != "iso3888_runs") continue;
    const std::size_t col = std::find(table.columns.begin(), table.columns.end(), "steps") - table.columns.begin();
    for (const auto& row : table.rows) j.steps += long(row.at(col));
  }
  return j;
}

Json iso3888(const std::string& vehicle, const Iso3888Job& job, const std::string& out) {
  const Json& s = job.summary;
  auto numOr = [](const Json& j) { return j.is_number() ? j.get<double>() : std::nan(""); };
  std::printf("  ISO 3888-2 %-12s highest passing entry speed %s m/s (%s km/h), lowest failing %s m/s, %zu runs, "
              "min clearance %s m, %s s\n",
              vehicle.c_str(), sig(numOr(s["highest_pass_m_s"])).c_str(), sig(numOr(s["highest_pass_km_h"])).c_str(),
              sig(numOr(s["lowest_fail_m_s"])).c_str(), s["runs"].size(), sig(numOr(s["best_min_clearance_m"]), 3).c_str(),
              sig(numOr(s["wall_time_s"]), 3).c_str());
  return {{"highest_pass_m_s", s["highest_pass_m_s"]}, {"lowest_fail_m_s", s["lowest_fail_m_s"]},
          {"top_of_bracket_passes", s["top_of_bracket_passes"]}, {"bracket_m_s", s["bracket_m_s"]},
          {"tolerance_m_s", s["tolerance_m_s"]}, {"runs", s["runs"].size()}, {"out_dir", out + "/iso3888_" + fileTag(vehicle)}};
}

/// The 2WS / 4WS table: one row per vehicle run, the App. A strategies ranked
/// per test (1 = best; ties share a rank) and overall by their mean rank (ties:
/// the ISO 3888-2 speed). Open loop except ISO 3888-2 (closed loop: path
/// controller, rear-steer law with its G1/G2 tracking). Ranked on: ISO 4138
/// limit a_y at R = 100 m (higher), ISO 7401 yaw response time (shorter), SWD
/// (pass; else the higher first failing amplitude), ISO 3888-2 highest passing
/// entry speed (higher). The bicycle, if run, is listed unranked.
void printRanking(const Json& summary, const std::vector<std::string>& vehicles, const std::string& csvPath) {
  struct Row {
    std::string name;
    double ay = NAN, k0 = NAN, lost = NAN, tr = NAN, tpk = NAN, os = NAN, swdScore = NAN, r1 = NAN, dlc = NAN;
    bool has4138 = false, has7401 = false, hasSwd = false, hasDlc = false;
    std::string swd = "-";
    int rank[4] = {0, 0, 0, 0};
    double mean = NAN;
  };
  auto num = [](const Json& j, const char* k) {
    return j.contains(k) && j[k].is_number() ? j[k].get<double>() : std::nan("");
  };
  std::vector<Row> rows;
  for (const auto& v : vehicles) {
    const Json& jv = summary[v];
    Row r;
    r.name = v;
    if ((r.has4138 = jv.contains("iso4138") && !jv["iso4138"].empty())) {
      const Json& j = jv["iso4138"][0];  // the first radius (R = 100 m in handling.json)
      r.ay = num(j, "limit_lateral_accel_m_s2"), r.k0 = num(j, "understeer_gradient_linear_deg_per_m_s2");
      r.lost = num(j, "stability_lost_lateral_accel_m_s2");
    }
    if ((r.has7401 = jv.contains("iso7401"))) {
      const Json& j = jv["iso7401"];
      r.tr = num(j, "yaw_response_time_s"), r.tpk = num(j, "yaw_peak_response_time_s"), r.os = num(j, "yaw_overshoot");
    }
    if ((r.hasSwd = jv.contains("sine_with_dwell"))) {
      const Json& j = jv["sine_with_dwell"];
      const bool pass = j["pass"].get<bool>();
      // Pass scores above every failing amplitude; a failure scores its amplitude.
      r.swdScore = pass ? 1e9 : num(j, "first_fail_factor");
      r.swd = pass ? "pass" : "FAIL " + j["first_fail"].get<std::string>();
      r.r1 = num(j, "max_yaw_ratio_1s");
    }
    if ((r.hasDlc = jv.contains("iso3888"))) r.dlc = 3.6 * num(jv["iso3888"], "highest_pass_m_s");
    rows.push_back(r);
  }
  // Competition ranks among the App. A rows ("4ws/..."), per test.
  auto rankBy = [&](int col, auto has, auto value, bool higherBetter) {
    for (auto& a : rows) {
      if (a.name.rfind("4ws/", 0) != 0 || !has(a) || !std::isfinite(value(a))) continue;
      int k = 1;
      for (const auto& b : rows)
        if (b.name.rfind("4ws/", 0) == 0 && has(b) && std::isfinite(value(b)) &&
            (higherBetter ? value(b) > value(a) : value(b) < value(a)))
          ++k;
      a.rank[col] = k;
    }
  };
  rankBy(0, [](const Row& r) { return r.has4138; }, [](const Row& r) { return r.ay; }, true);
  rankBy(1, [](const Row& r) { return r.has7401; }, [](const Row& r) { return r.tr; }, false);
  rankBy(2, [](const Row& r) { return r.hasSwd; }, [](const Row& r) { return r.swdScore; }, true);
  rankBy(3, [](const Row& r) { return r.hasDlc; }, [](const Row& r) { return r.dlc; }, true);
  for (auto& r : rows) {
    double sum = 0;
    int n = 0;
    for (int k : r.rank)
      if (k > 0) sum += k, ++n;
    if (n) r.mean = sum / n;
  }
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    const bool ra = std::isfinite(a.mean), rb = std::isfinite(b.mean);
    if (ra != rb) return ra;
    if (ra && a.mean != b.mean) return a.mean < b.mean;
    return (std::isfinite(a.dlc) ? a.dlc : -1) > (std::isfinite(b.dlc) ? b.dlc : -1);
  });
  auto cell = [](const std::string& v, int rank) { return rank > 0 ? v + " (" + std::to_string(rank) + ")" : v; };
  std::printf("\n  2WS / 4WS (App. A vehicle; rank per test in parentheses, 1 = best; overall = mean rank)\n");
  std::printf("  %-4s %-14s | %-16s %-9s %-10s | %-12s %-10s %-9s | %-18s %-8s | %-14s\n", "rank", "vehicle",
              "4138 ay_lim m/s2", "K0 d/mps2", "unstable", "7401 t_r90 s", "t_peak s", "overshoot", "SWD", "r1.0max",
              "3888-2 km/h");
  // The same table as CSV (numbers in shortest round-trip form; empty = no value).
  OutputFile csv(csvPath);
  csv << "place,vehicle,iso4138_limit_lateral_accel_m_s2,iso4138_rank,understeer_gradient_zero_deg_per_m_s2,"
         "stability_lost_lateral_accel_m_s2,iso7401_yaw_response_time_s,iso7401_rank,yaw_peak_response_time_s,"
         "yaw_overshoot,swd,swd_rank,max_yaw_ratio_1s,iso3888_highest_pass_km_h,iso3888_rank,mean_rank\n";
  auto field = [](double v) { return std::isfinite(v) ? formatValue(v) : std::string(); };
  auto rank = [](int k) { return k > 0 ? std::to_string(k) : std::string(); };
  int place = 0;
  for (const auto& r : rows) {
    const std::string rk = std::isfinite(r.mean) ? std::to_string(++place) : "-";
    csv << (rk == "-" ? "" : rk) << ',' << r.name << ',' << field(r.ay) << ',' << rank(r.rank[0]) << ',' << field(r.k0)
        << ',' << field(r.lost) << ',' << field(r.tr) << ',' << rank(r.rank[1]) << ',' << field(r.tpk) << ','
        << field(r.os) << ',' << (r.hasSwd ? r.swd : "") << ',' << rank(r.rank[2]) << ',' << field(r.r1) << ','
        << field(r.dlc) << ',' << rank(r.rank[3]) << ',' << field(r.mean) << '\n';
    std::printf("  %-4s %-14s | %-16s %-9s %-10s | %-12s %-10s %-9s | %-18s %-8s | %-14s\n", rk.c_str(),
                r.name.c_str(), cell(sig(r.ay), r.rank[0]).c_str(), sig(r.k0, 3).c_str(),
                r.has4138 ? (std::isfinite(r.lost) ? sig(r.lost, 3).c_str() : "never") : "-",
                cell(sig(r.tr, 3), r.rank[1]).c_str(), r.has7401 ? sig(r.tpk, 3, "no peak").c_str() : "-",
                r.has7401 ? (sig(100 * r.os, 2) + " %").c_str() : "-", cell(r.swd, r.rank[2]).c_str(),
                sig(r.r1, 3).c_str(), cell(sig(r.dlc, 3), r.rank[3]).c_str());
  }
  std::printf("  K0 d/mps2: understeer gradient at zero a_y, deg/(m/s^2); unstable: a_y (m/s^2) where the "
              "R = 100 m sweep loses stability; SWD: pass, or the first failing amplitude and why (spin, r1.0 / r1.75 "
              "ratio, disp); r1.0max: largest 1.0 s yaw-rate ratio of the completed runs\n");
  csv.commit();
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("handling", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("handling.json"), "study data file")(
        "test", po::value<std::string>()->default_value("iso4138,iso7401,swd,iso3888"),
        "comma-separated tests: iso4138, iso7401, swd, iso3888")(
        "vehicle", po::value<std::string>()->default_value("4ws/2ws,4ws/linear,4ws/nonlinear,bicycle"),
        "comma-separated vehicles: 4ws/2ws, 4ws/linear, 4ws/nonlinear, bicycle")(
        "check", "ISO 7401: cross-check the frequency response with sine-steer simulations")(
        "threads", po::value<int>()->default_value(0),
        "worker threads for the independent runs (0: one per core); the outputs do not depend on it")(
        "no-plots", "skip the PNG plots");
    const auto vm = study::parse("handling", "standard handling tests (ISO 4138, ISO 7401, sine with dwell, ISO 3888-2)",
                                 argc, argv, opts);
    Config c{ParamReader::fromFile(vm["data"].as<std::string>()), {}, {}, {}};
    c.fourws_data = c.data.string("vehicle_data");
    c.bicycle_data = c.data.string("bicycle_data");
    c.setup.linear = LinearBicycleParams::fromParams(c.data.child("linear_bicycle"));
    c.setup.kr_table = c.data.string("kr_table");
    c.setup.tire_width_m = c.data.number("tire_width_m");
    const auto tests = splitList(vm["test"].as<std::string>());
    const auto vehicles = splitList(vm["vehicle"].as<std::string>());
    for (const auto& t : tests)
      if (t != "iso4138" && t != "iso7401" && t != "swd" && t != "iso3888")
        throw Error("--test: unknown test '" + t + "'; known: iso4138, iso7401, swd, iso3888");
    for (const auto& v : vehicles)
      if (v != "bicycle" && v != "4ws/2ws" && v != "4ws/linear" && v != "4ws/nonlinear")
        throw Error("--vehicle: unknown vehicle '" + v + "'; known: 4ws/2ws, 4ws/linear, 4ws/nonlinear, bicycle");
    int threads = vm["threads"].as<int>();
    if (threads < 0) throw Error("--threads must be non-negative, got " + std::to_string(threads));
    if (threads == 0) threads = hardwareThreads();
    const std::string out = study::outputDir(vm, "handling");
    const bool plots = !vm.count("no-plots");
    const bool check = vm.count("check") > 0;
    auto has = [&](const char* t) { return std::find(tests.begin(), tests.end(), t) != tests.end(); };
    const auto wall0 = std::chrono::steady_clock::now();
    const double cpu0 = processCpuSeconds();
    const std::size_t nv = vehicles.size();

    // Every independent run is a job (runJobs: the sweep runner's threads),
    // each building its own vehicle and writing only its own slot; the reports
    // are made afterwards in vehicle and test order, so the outputs do not
    // depend on the number of threads. Round 1: the sine with dwell's angle A
    // per vehicle (its amplitude runs need it). Round 2: everything else, the
    // long ISO 3888-2 searches (sequential rounds inside) first.
    const SineWithDwellSettings swdSet = SineWithDwellSettings::fromParams(c.data.child("sine_with_dwell"));
    std::vector<SineWithDwellResult> swd(nv);
    if (has("swd"))
      runJobs(nv, threads, [&](std::size_t v) {
        swd[v].angle_A_rad = calcSineWithDwellAngle(build(c, vehicles[v])->vehicle, swdSet);
      });
    const std::vector<double> radii = c.data.child("iso4138").numbers("radii_m");
    const std::vector<double> checkFreqs = c.data.child("iso7401").numbers("check_frequencies_Hz");
    std::vector<Iso3888Job> dlc(nv);
    std::vector<std::vector<ConstantRadiusResult>> cr(nv, std::vector<ConstantRadiusResult>(radii.size()));
    std::vector<Iso7401Run> step(nv);
    std::vector<std::vector<SineCheck>> checks(nv, std::vector<SineCheck>(check ? checkFreqs.size() : 0));
    std::vector<std::vector<double>> factors(nv);
    std::vector<std::function<void()>> jobs;
    for (std::size_t v = 0; v < nv; ++v)
      if (has("iso3888")) jobs.push_back([&, v] { dlc[v] = runIso3888Scene(c, vehicles[v], out, plots); });
    for (std::size_t v = 0; v < nv; ++v) {
      if (!has("swd")) continue;
      factors[v] = calcSineWithDwellFactors(swdSet, swd[v].angle_A_rad);
      swd[v].runs.resize(factors[v].size());
      for (std::size_t k = 0; k < factors[v].size(); ++k)
        jobs.push_back([&, v, k] {
          swd[v].runs[k] =
              runSineWithDwellAmplitude(build(c, vehicles[v])->vehicle, swdSet, swd[v].angle_A_rad, factors[v][k]);
        });
    }
    for (std::size_t v = 0; v < nv; ++v) {
      if (has("iso7401")) {
        jobs.push_back([&, v] { step[v] = runIso7401(c, vehicles[v]); });
        for (std::size_t k = 0; k < checks[v].size(); ++k)
          jobs.push_back([&, v, k] { checks[v][k] = runSineCheck(c, vehicles[v], checkFreqs[k]); });
      }
      if (has("iso4138"))
        for (std::size_t k = 0; k < radii.size(); ++k)
          jobs.push_back([&, v, k] { cr[v][k] = runIso4138(c, vehicles[v], radii[k]); });
    }
    runJobs(jobs.size(), threads, [&](std::size_t i) { jobs[i](); });

    // Reports, counts.
    long simRuns = 0, steps = 0, residuals = 0;
    Json summary = Json::object();
    for (std::size_t v = 0; v < nv; ++v) {
      Json jv = Json::object();
      for (const auto& t : tests) {
        if (t == "iso4138") {
          jv["iso4138"] = iso4138(c, vehicles[v], cr[v], out, plots);
          for (const auto& r : cr[v]) residuals += r.residual_evaluations;
        }
        if (t == "iso7401") {
          jv["iso7401"] = iso7401(c, vehicles[v], step[v], checks[v], out, plots, check);
          simRuns += 1 + long(checks[v].size()), steps += step[v].step.run.steps;
          for (const auto& k : checks[v]) steps += k.sim.run.steps;
        }
        if (t == "swd") {
          SineWithDwellResult& r = swd[v];
          r.pass = true;
          for (const auto& q : r.runs) r.pass = r.pass && q.pass, steps += q.run.steps;
          simRuns += long(r.runs.size());
          jv["sine_with_dwell"] = sineWithDwell(c, vehicles[v], r, out, plots);
        }
        if (t == "iso3888") {
          jv["iso3888"] = iso3888(vehicles[v], dlc[v], out);
          simRuns += long(dlc[v].summary["runs"].size()), steps += dlc[v].steps;
        }
      }
      summary[vehicles[v]] = jv;
    }
    printRanking(summary, vehicles, out + "/table.csv");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const double cpu = processCpuSeconds() - cpu0;
    std::printf("\n  handling: %zu jobs on %d threads: %ld simulation runs (%ld integrator steps), %ld steady-state "
                "residual evaluations; wall %.1f s, CPU %.1f s (all threads)\n",
                jobs.size() + (has("swd") ? nv : 0), threads, simRuns, steps, residuals, wall, cpu);
    summary["cost"] = {{"threads", threads}, {"jobs", jobs.size() + (has("swd") ? nv : 0)},
                       {"simulation_runs", simRuns}, {"integrator_steps", steps},
                       {"steady_state_residual_evaluations", residuals}, {"wall_time_s", wall}, {"cpu_time_s", cpu}};
    study::writeJson(out + "/summary.json", summary);
  });
}
