// The handling tests as analyses a scene file names ("analysis": {"type":
// "iso4138_constant_radius" | "iso7401" | "sine_with_dwell" | "iso3888_2" |
// "vehicle_report"}), each on the scene's built scene (its vehicle and every
// plugin it lists, plugin-library types included). iso3888_2 runs the scene
// itself (closed loop, its own plugins; the analysis sets the path controller's
// path and the entry speed). The open-loop tests replace the scene's steering
// constraints, speed holds and controllers with their own programmable
// steering and speed hold (buildHandlingScene, handling_vehicles.h) and list
// what they replaced and added in the summary key "plugins".
#include <algorithm>
#include <chrono>
#include <cmath>

#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/handling/iso3888.h"
#include "vdyn/handling/iso4138.h"
#include "vdyn/handling/iso7401.h"
#include "vdyn/handling/sine_with_dwell.h"
#include "vdyn/vehicles/handling_vehicles.h"

namespace vdyn {

namespace {
const double kDeg = SimTK::Pi / 180;

/// ISO 7401's frequency-response keys (one table: read and listed).
struct FrequencyKeys {
  double frequency_from_Hz = 0.1, frequency_to_Hz = 4.0;
  int frequency_count = 25;
  static const FieldTable<FrequencyKeys>& fields() {
    using F = FrequencyKeys;
    static const auto t = FieldTable<F>()
                              .number("frequency_from_Hz", &F::frequency_from_Hz, "Hz", "lowest frequency")
                              .number("frequency_to_Hz", &F::frequency_to_Hz, "Hz", "highest frequency")
                              .integer("frequency_count", &F::frequency_count, "", "log-spaced frequencies");
    return t;
  }
};

/// vehicle_report's keys.
struct TravelKeys {
  double travel_range_m = 0.08, travel_step_m = 0.01;
  static const FieldTable<TravelKeys>& fields() {
    using T = TravelKeys;
    static const auto t = FieldTable<T>()
                              .number("travel_range_m", &T::travel_range_m, "m", "wheel travel +- this")
                              .number("travel_step_m", &T::travel_step_m, "m", "travel step");
    return t;
  }
};

/// iso3888_2's key besides Iso3888Settings'.
struct Iso3888Keys {
  double tire_width_m = 0.195;
  static const FieldTable<Iso3888Keys>& fields() {
    static const auto t = FieldTable<Iso3888Keys>().number(
        "tire_width_m", &Iso3888Keys::tire_width_m, "m", "tire section width (vehicle width = track + this)");
    return t;
  }
};

Json nullIfNan(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

/// ISO 4138's panels against lateral acceleration: each quantity on the
/// branch up to the limit (the fold, marked), the gradients' axes scaled to
/// the points below 90 % of the limit, where a gradient is defined (at the
/// fold d a_y -> 0 and the gradients grow without bound).
PlotSpec iso4138Figure(const ConstantRadiusResult& r, const std::string& vehicle) {
  const double limit = r.limit_found ? r.limit_lateral_accel_m_s2 : NAN;
  const double xMax = std::isfinite(limit) ? 1.04 * limit : NAN;
  // The range of a gradient over the points where it is defined, widened by 15 %.
  auto gradientRange = [&](auto get, double& lo, double& hi) {
    lo = INFINITY, hi = -INFINITY;
    for (const auto& p : r.points) {
      const double g = get(p) / kDeg;
      if (!std::isfinite(g) || (std::isfinite(limit) && p.lateral_accel_m_s2 > 0.9 * limit)) continue;
      lo = std::min(lo, g), hi = std::max(hi, g);
    }
    if (!(lo <= hi)) {
      lo = hi = NAN;
      return;
    }
    const double pad = 0.15 * std::max(hi - lo, 0.05 * std::max(std::abs(lo), std::abs(hi)) + 1e-9);
    lo -= pad, hi += pad;
  };
  std::vector<PlotMarker> marks;
  if (std::isfinite(limit)) marks.push_back({limit, "limit " + formatValue(std::round(limit * 1000) / 1000) + " m/s^2"});
  auto panel = [&](std::string title, std::string ylabel, std::vector<PlotSeries> series) {
    PlotSpec p;
    p.title = std::move(title), p.xlabel = "lateral acceleration a_y (m/s^2)", p.ylabel = std::move(ylabel);
    p.series = std::move(series);
    p.points = true, p.x_min = 0, p.x_max = xMax, p.markers = marks;
    return p;
  };
  const std::string x = "lateral_accel_m_s2";
  PlotSpec f;
  f.name = "iso4138";
  f.title = "ISO 4138 constant radius " + formatValue(r.radius_m) + " m: " + vehicle;
  f.columns = 3;
  f.panels = {panel("front steer angle", "angle (deg)",
                    {{"iso4138", x, "front_deg", "front angle"}, {"iso4138", x, "delta_minus_l_over_R_deg", "front - l/R"}}),
              panel("understeer gradient", "deg/(m/s^2)", {{"iso4138", x, "understeer_gradient_deg_per_m_s2", ""}}),
              panel("roll angle", "roll (deg)", {{"iso4138", x, "roll_deg", ""}}),
              panel("roll gradient", "deg/(m/s^2)", {{"iso4138", x, "roll_gradient_deg_per_m_s2", ""}}),
              panel("side slip", "side slip (deg)", {{"iso4138", x, "side_slip_deg", ""}}),
              panel("side-slip gradient", "deg/(m/s^2)", {{"iso4138", x, "side_slip_gradient_deg_per_m_s2", ""}}),
              panel("least-damped eigenvalue (< 0: stable)", "real part (1/s)",
                    {{"iso4138", x, "least_damped_re_per_s", ""}}),
              panel("speed", "speed (m/s)", {{"iso4138", x, "speed_m_s", ""}})};
  gradientRange([](const ConstantRadiusPoint& p) { return p.understeer_gradient_rad_per_m_s2; }, f.panels[1].y_min,
                f.panels[1].y_max);
  gradientRange([](const ConstantRadiusPoint& p) { return p.roll_gradient_rad_per_m_s2; }, f.panels[3].y_min,
                f.panels[3].y_max);
  gradientRange([](const ConstantRadiusPoint& p) { return p.side_slip_gradient_rad_per_m_s2; }, f.panels[5].y_min,
                f.panels[5].y_max);
  return f;
}

/// ISO 7401's frequency response as Bode plots: gains (ratio) and phases
/// (deg) on a logarithmic frequency axis, 1 Hz and the yaw resonance marked.
PlotSpec bodeFigure(const FrequencyResponseResult& fr, const std::string& vehicle, double speed_m_s) {
  std::vector<PlotMarker> marks = {{1.0, "1 Hz"}};
  if (std::isfinite(fr.yaw_resonance_frequency_Hz))
    marks.push_back({fr.yaw_resonance_frequency_Hz,
                     "yaw resonance " + formatValue(std::round(fr.yaw_resonance_frequency_Hz * 1000) / 1000) + " Hz"});
  auto panel = [&](std::string title, std::string ylabel, std::string y) {
    PlotSpec p;
    p.title = std::move(title), p.xlabel = "steering frequency (Hz)", p.ylabel = std::move(ylabel);
    p.series = {{"frequency_response", "frequency_Hz", y, ""}};
    p.logx = true, p.markers = marks;
    return p;
  };
  PlotSpec f;
  f.name = "frequency_response";
  f.title = "ISO 7401 frequency response (linearised about straight running at " + formatValue(speed_m_s) +
            " m/s): " + vehicle;
  f.columns = 2;
  f.panels = {panel("yaw-rate gain r / delta", "gain (1/s)", "yaw_gain_1_per_s"),
              panel("yaw-rate phase", "phase (deg)", "yaw_phase_deg"),
              panel("lateral-acceleration gain a_y / delta", "gain ((m/s^2)/rad)", "ay_gain_m_s2_per_rad"),
              panel("lateral-acceleration phase", "phase (deg)", "ay_phase_deg")};
  return f;
}

class ConstantRadiusAnalysis : public Analysis {
 public:
  explicit ConstantRadiusAnalysis(const ParamReader& r)
      : Analysis("iso4138_constant_radius"), c_(HandlingSetup::fromParams(r)) {
    s_ = ConstantRadiusSettings::fromParams(r);
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    auto b = buildHandlingScene(ctx.description, c_);
    const ConstantRadiusResult r = runConstantRadius(b->vehicle, s_);
    AnalysisResult res;
    Table t;
    t.columns = {"speed_m_s", "lateral_accel_m_s2", "front_deg", "rear_deg", "side_slip_deg", "roll_deg",
                 "yaw_rate_rad_s", "understeer_gradient_deg_per_m_s2", "delta_minus_l_over_R_deg", "stable",
                 "least_damped_re_per_s", "speed_hold_force_N", "roll_gradient_deg_per_m_s2",
                 "side_slip_gradient_deg_per_m_s2"};
    for (const auto& p : r.points)
      t.rows.push_back({p.speed_m_s, p.lateral_accel_m_s2, p.front_rad / kDeg, p.rear_rad / kDeg, p.side_slip_rad / kDeg,
                        p.roll_rad / kDeg, p.yaw_rate_rad_s, p.understeer_gradient_rad_per_m_s2 / kDeg,
                        (p.front_rad - r.wheelbase_m / r.radius_m) / kDeg, double(p.stable), p.least_damped.real(),
                        p.speed_hold_force_N, p.roll_gradient_rad_per_m_s2 / kDeg,
                        p.side_slip_gradient_rad_per_m_s2 / kDeg});
    res.tables.push_back({"iso4138", t});
    res.plots.push_back(iso4138Figure(r, b->vehicle.name));
    res.summary = {{"vehicle", b->vehicle.name},
                   {"plugins", b->describePlugins()},
                   {"radius_m", r.radius_m},
                   {"points", r.points.size()},
                   {"limit_found", r.limit_found},
                   {"limit_speed_m_s", r.limit_speed_m_s},
                   {"limit_lateral_accel_m_s2", r.limit_lateral_accel_m_s2},
                   {"understeer_gradient_linear_deg_per_m_s2", r.understeer_gradient_linear_rad_per_m_s2 / kDeg},
                   {"roll_gradient_linear_deg_per_m_s2", r.roll_gradient_linear_rad_per_m_s2 / kDeg},
                   {"side_slip_gradient_linear_deg_per_m_s2", r.side_slip_gradient_linear_rad_per_m_s2 / kDeg},
                   {"stability_lost_speed_m_s", nullIfNan(r.stability_lost_speed_m_s)},
                   {"stability_lost_lateral_accel_m_s2", nullIfNan(r.stability_lost_lateral_accel_m_s2)},
                   {"solve_wall_time_s", r.solve_wall_time_s},
                   {"wall_time_s", r.wall_time_s}};
    return res;
  }

 private:
  HandlingSetup c_;
  ConstantRadiusSettings s_;
};

class Iso7401Analysis : public Analysis {
 public:
  explicit Iso7401Analysis(const ParamReader& r) : Analysis("iso7401"), c_(HandlingSetup::fromParams(r)) {
    s_ = StepSteerSettings::fromParams(r);
    const FrequencyKeys k = FrequencyKeys::fields().read(r);
    f0_ = k.frequency_from_Hz, f1_ = k.frequency_to_Hz, n_ = k.frequency_count;
    logFrequencies(f0_, f1_, n_);
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    auto b = buildHandlingScene(ctx.description, c_);
    const StepSteerResult st = runStepSteer(b->vehicle, s_);
    const FrequencyResponseResult fr = calcSteeringFrequencyResponse(b->vehicle, s_.speed_m_s, logFrequencies(f0_, f1_, n_));
    AnalysisResult res;
    Table step;
    step.columns = {"t_s", "front_rad", "rear_rad", "yaw_rate_rad_s", "lateral_accel_m_s2"};
    const auto& h = st.history;
    for (std::size_t i = 0; i < h.t_s.size(); ++i)
      step.rows.push_back({h.t_s[i], h.front_rad[i], h.rear_rad[i], h.yaw_rate_rad_s[i], h.lateral_accel_m_s2[i]});
    Table f;
    f.columns = {"frequency_Hz", "yaw_gain_1_per_s", "yaw_phase_deg", "ay_gain_m_s2_per_rad", "ay_phase_deg"};
    for (const auto& q : fr.points)
      f.rows.push_back({q.frequency_Hz, q.yaw_gain_1_per_s, q.yaw_phase_deg, q.ay_gain_m_s2_per_rad, q.ay_phase_deg});
    res.tables.push_back({"step_steer", step});
    res.tables.push_back({"frequency_response", f});
    res.plots.push_back(bodeFigure(fr, b->vehicle.name, s_.speed_m_s));
    res.summary = {{"vehicle", b->vehicle.name},
                   {"plugins", b->describePlugins()},
                   {"front_deg", st.front_rad / kDeg},
                   {"steady_yaw_rate_rad_s", st.steady_yaw_rate_rad_s},
                   {"yaw_rate_gain_1_per_s", st.yaw_rate_gain_1_per_s},
                   {"yaw_response_time_s", st.yaw_response_time_s},
                   {"yaw_peak_response_time_s", nullIfNan(st.yaw_peak_response_time_s)},
                   {"yaw_overshoot", st.yaw_overshoot},
                   {"lateral_accel_response_time_s", st.lateral_accel_response_time_s},
                   {"lateral_accel_overshoot", st.lateral_accel_overshoot},
                   {"linear_yaw_gain_zero_1_per_s", fr.yaw_gain_zero_1_per_s},
                   {"yaw_rate_resonance_frequency_Hz", nullIfNan(fr.yaw_resonance_frequency_Hz)},
                   {"yaw_rate_peak_ratio", nullIfNan(fr.yaw_peak_ratio)},
                   {"yaw_rate_phase_1Hz_deg", fr.yaw_phase_1Hz_deg},
                   {"lateral_accel_phase_1Hz_deg", fr.ay_phase_1Hz_deg},
                   {"lateral_accel_gain_ratio_1Hz", fr.ay_gain_ratio_1Hz},
                   {"linear_stable", fr.stable}};
    return res;
  }

 private:
  HandlingSetup c_;
  StepSteerSettings s_;
  double f0_, f1_;
  int n_;
};

class SineWithDwellAnalysis : public Analysis {
 public:
  explicit SineWithDwellAnalysis(const ParamReader& r)
      : Analysis("sine_with_dwell"), c_(HandlingSetup::fromParams(r)), s_(SineWithDwellSettings::fromParams(r)) {}

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    auto b = buildHandlingScene(ctx.description, c_);
    // The amplitude runs on the machine's cores, each on its own instance (the result does not depend on it).
    const SineWithDwellResult r =
        runSineWithDwell(makeHandlingVehicleMaker(ctx.description, c_), s_, hardwareThreads());
    AnalysisResult res;
    Table t;
    // A spun-out or failed run has no ratios (NaN cells, the reason in the summary).
    t.columns = {"factor", "amplitude_deg", "completed", "spun_out", "peak_yaw_rate_rad_s", "yaw_ratio_1s",
                 "yaw_ratio_1_75s", "lateral_displacement_m", "pass"};
    Json runs = Json::array();
    for (const auto& q : r.runs) {
      t.rows.push_back({q.factor, q.amplitude_rad / kDeg, double(q.completed), double(q.spun_out),
                        q.completed ? q.peak_yaw_rate_rad_s : NAN, q.completed ? q.yaw_ratio_1s : NAN,
                        q.completed ? q.yaw_ratio_175 : NAN, q.completed ? q.lateral_displacement_m : NAN, double(q.pass)});
      Json j = {{"factor", q.factor}, {"completed", q.completed}, {"spun_out", q.spun_out}, {"pass", q.pass}};
      if (!q.completed) j["reason"] = q.reason;
      runs.push_back(j);
    }
    res.tables.push_back({"sine_with_dwell", t});
    res.summary = {{"vehicle", b->vehicle.name}, {"plugins", b->describePlugins()}, {"angle_A_deg", r.angle_A_rad / kDeg}, {"pass", r.pass}, {"runs", runs}};
    return res;
  }

 private:
  HandlingSetup c_;
  SineWithDwellSettings s_;
};

Table runTrajectoryTable(const Iso3888Run& q) {
  Table t;
  t.columns = {"t_s", "x_m", "y_m", "yaw_deg", "front_deg", "rear_deg", "path_error_m"};
  for (std::size_t i = 0; i < q.t_s.size(); ++i)
    t.rows.push_back({q.t_s[i], q.x_m[i], q.y_m[i], q.yaw_rad[i] / kDeg, q.front_rad[i] / kDeg, q.rear_rad[i] / kDeg,
                      q.path_error_m[i]});
  return t;
}

/// Body corner tracks of a run (for the course plot): front-left, front-right,
/// rear-right, rear-left corners' X and Y.
Table cornerTable(const Iso3888Run& q, const BodyOutline& body) {
  Table t;
  t.columns = {"x_m", "fl_x_m", "fl_y_m", "fr_x_m", "fr_y_m", "rr_x_m", "rr_y_m", "rl_x_m", "rl_y_m"};
  for (std::size_t i = 0; i < q.t_s.size(); ++i) {
    const auto c = body.corners(q.x_m[i], q.y_m[i], q.yaw_rad[i]);
    t.rows.push_back({q.x_m[i], c[0][0], c[0][1], c[1][0], c[1][1], c[2][0], c[2][1], c[3][0], c[3][1]});
  }
  return t;
}

class Iso3888Analysis : public Analysis {
 public:
  explicit Iso3888Analysis(const ParamReader& r) : Analysis("iso3888_2"), s_(Iso3888Settings::fromParams(r)) {
    tire_width_m_ = Iso3888Keys::fields().read(r).tire_width_m;
    requirePositive(tire_width_m_, r.at("tire_width_m"));
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    const auto t0 = std::chrono::steady_clock::now();
    const VehicleFootprint fp = calcVehicleFootprint(*ctx.built.vehicle, tire_width_m_);
    const Iso3888Result r = findHighestPassingSpeed(ctx.description, s_, fp, hardwareThreads());
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (ctx.animation) {
      // vdyn run --animation: the highest passing run once more, recorded
      // (the bisection's runs record nothing). A run is deterministic: the
      // same samples, or the animation would show another run than reported.
      const Iso3888Run& best = r.runs.at(r.best_run);
      const Iso3888Run again = runIso3888(ctx.description, s_, r.layout, r.body, best.speed_m_s, ctx.animation);
      if (again.x_m != best.x_m || again.y_m != best.y_m || again.yaw_rad != best.yaw_rad)
        throw Error(ctx.description.path() + ": ISO 3888-2 --animation: the run at " + formatValue(best.speed_m_s) +
                    " m/s repeated gave other samples than the reported one");
    }
    AnalysisResult res;
    Table runs;
    runs.columns = {"speed_m_s", "speed_km_h", "completed", "pass", "cone_lines_struck", "min_clearance_m",
                    "exit_speed_m_s", "max_path_error_m", "peak_lateral_accel_m_s2", "peak_front_steer_deg", "steps"};
    Json jr = Json::array();
    for (const auto& q : r.runs) {
      runs.rows.push_back({q.speed_m_s, q.speed_m_s * 3.6, double(q.completed), double(q.pass),
                           double(q.cones.strikes.size()), q.completed ? q.cones.min_clearance_m : NAN,
                           q.completed ? q.exit_speed_m_s : NAN, q.completed ? q.max_path_error_m : NAN,
                           q.completed ? q.peak_lateral_accel_m_s2 : NAN, q.completed ? q.peak_front_steer_deg : NAN,
                           double(q.run.steps)});
      Json j = {{"speed_m_s", q.speed_m_s}, {"pass", q.pass}, {"completed", q.completed}};
      if (!q.completed) j["reason"] = q.reason;
      Json st = Json::array();
      for (const auto& c : q.cones.strikes)
        st.push_back({{"section", c.section}, {"side", c.side}, {"t_s", c.t_s}, {"x_m", c.x_m}});
      j["strikes"] = st;
      if (q.completed) j["min_clearance_m"] = q.cones.min_clearance_m;
      jr.push_back(j);
    }
    res.tables.push_back({"iso3888_runs", runs});
    Table cones;
    cones.columns = {"x_m", "left_y_m", "right_y_m"};
    Json lanes = Json::array();
    for (const auto& l : r.layout.lanes) {
      cones.rows.push_back({l.x_start_m, l.y_left_m, l.y_right_m});
      cones.rows.push_back({l.x_end_m, l.y_left_m, l.y_right_m});
      cones.rows.push_back({NAN, NAN, NAN});  // a gap between sections in the plot
      lanes.push_back({{"section", l.section}, {"x_start_m", l.x_start_m}, {"x_end_m", l.x_end_m},
                       {"y_right_m", l.y_right_m}, {"y_left_m", l.y_left_m}, {"width_m", l.width()}});
    }
    res.tables.push_back({"iso3888_cones", cones});
    const Iso3888Run& best = r.runs.at(r.best_run);
    res.tables.push_back({"iso3888_best", runTrajectoryTable(best)});
    res.tables.push_back({"iso3888_best_corners", cornerTable(best, r.body)});
    PlotSpec course{"iso3888_course", "ISO 3888-2: highest passing entry speed " + formatValue(best.speed_m_s) + " m/s",
                    "X (m)", "Y (m)",
                    {{"iso3888_cones", "x_m", "left_y_m", "left cone lines"},
                     {"iso3888_cones", "x_m", "right_y_m", "right cone lines"},
                     {"iso3888_best_corners", "fl_x_m", "fl_y_m", "front-left corner"},
                     {"iso3888_best_corners", "fr_x_m", "fr_y_m", "front-right corner"},
                     {"iso3888_best_corners", "rr_x_m", "rr_y_m", "rear-right corner"},
                     {"iso3888_best_corners", "rl_x_m", "rl_y_m", "rear-left corner"}}};
    std::vector<PlotSeries> steerFail;
    if (r.first_fail_run >= 0) {
      const Iso3888Run& fail = r.runs[r.first_fail_run];
      if (!fail.t_s.empty()) {
        res.tables.push_back({"iso3888_fail", runTrajectoryTable(fail)});
        res.tables.push_back({"iso3888_fail_corners", cornerTable(fail, r.body)});
        course.series.push_back({"iso3888_fail_corners", "fl_x_m", "fl_y_m",
                                 "front-left corner at " + formatValue(fail.speed_m_s) + " m/s (fails)"});
        course.series.push_back({"iso3888_fail_corners", "rr_x_m", "rr_y_m",
                                 "rear-right corner at " + formatValue(fail.speed_m_s) + " m/s (fails)"});
        steerFail = {{"iso3888_fail", "t_s", "front_deg", "front, " + formatValue(fail.speed_m_s) + " m/s (fails)"}};
      }
    }
    res.plots.push_back(course);
    PlotSpec steer{"iso3888_steering", "ISO 3888-2: road-wheel angles", "t (s)", "angle (deg)",
                   {{"iso3888_best", "t_s", "front_deg", "front, " + formatValue(best.speed_m_s) + " m/s"},
                    {"iso3888_best", "t_s", "rear_deg", "rear, " + formatValue(best.speed_m_s) + " m/s"}}};
    steer.series.insert(steer.series.end(), steerFail.begin(), steerFail.end());
    res.plots.push_back(steer);
    res.plots.push_back({"iso3888_runs", "ISO 3888-2 bisection: pass (1) / fail (0) against entry speed",
                         "entry speed (m/s)", "pass", {{"iso3888_runs", "speed_m_s", "pass", "pass"}}, false, false, true});
    res.summary = {{"vehicle_width_m", r.layout.vehicle_width_m},
                   {"body", {{"front_x_m", r.body.front_x_m}, {"rear_x_m", r.body.rear_x_m},
                             {"half_width_m", r.body.half_width_m}}},
                   {"lanes", lanes},
                   {"bracket_m_s", {s_.speed_low_m_s, s_.speed_high_m_s}},
                   {"tolerance_m_s", s_.speed_tolerance_m_s},
                   {"highest_pass_m_s", r.highest_pass_m_s},
                   {"highest_pass_km_h", r.highest_pass_m_s * 3.6},
                   {"lowest_fail_m_s", nullIfNan(r.lowest_fail_m_s)},
                   {"top_of_bracket_passes", r.top_passes},
                   {"best_min_clearance_m", best.cones.min_clearance_m},
                   {"best_exit_speed_m_s", best.exit_speed_m_s},
                   {"coasting", s_.speed_hold.empty()},
                   {"runs", jr},
                   {"wall_time_s", wall}};
    return res;
  }

 private:
  Iso3888Settings s_;
  double tire_width_m_;
};

class VehicleReportAnalysis : public Analysis {
 public:
  explicit VehicleReportAnalysis(const ParamReader& r) : Analysis("vehicle_report") {
    const TravelKeys k = TravelKeys::fields().read(r);
    range_ = k.travel_range_m, step_ = k.travel_step_m;
    requirePositive(range_, r.at("travel_range_m"));
    requirePositive(step_, r.at("travel_step_m"));
  }

 protected:
  AnalysisResult DoRun(const AnalysisContext& ctx) const override {
    std::vector<double> travels;
    for (double z = -range_; z <= range_ + 1e-12; z += step_) travels.push_back(std::abs(z) < 1e-12 ? 0.0 : z);
    const VehicleReport rep = makeVehicleReport(ctx.description, travels);
    AnalysisResult res;
    Json loads = Json::object();
    for (const auto& [n, f] : rep.corner_loads_N) loads[n] = f;
    res.summary = {{"vehicle", rep.vehicle},
                   {"method", rep.method},
                   {"iterations", rep.iterations},
                   {"corner_loads_N", loads},
                   {"front_axle_load_N", rep.front_axle_load_N},
                   {"rear_axle_load_N", rep.rear_axle_load_N},
                   {"total_load_N", rep.total_load_N},
                   {"weight_N", rep.weight_N},
                   {"chassis_origin_height_m", rep.chassis_origin_height_m},
                   {"com_height_m", rep.com_height_m}};
    if (!rep.axle_contact_x_m.empty()) {
      Json x = Json::object();
      for (const auto& [n, v] : rep.axle_contact_x_m) x[n] = v;
      res.summary["com_x_m"] = rep.com_x_m;
      res.summary["axle_contact_x_m"] = x;
      if (rep.axle_contact_x_m.size() == 2) res.summary["front_axle_load_from_moments_N"] = rep.front_axle_load_from_moments_N;
    }
    if (!rep.added_plugins.empty() || !rep.replaced_plugins.empty())
      res.summary["plugins"] = {{"replaced", rep.replaced_plugins}, {"added", rep.added_plugins}};
    for (const auto& [axle, why] : rep.kinematics_not_swept) res.summary["kinematics_not_swept"][axle] = why;
    for (const auto& [axle, pts] : rep.kinematics) {
      Table t;
      t.columns = {"travel_m", "camber_deg", "toe_in_deg", "track_change_m", "recession_m", "wheel_rate_N_per_m",
                   "roll_centre_height_m"};
      for (const auto& p : pts)
        t.rows.push_back({p.travel_m, p.camber_rad / kDeg, p.toe_rad / kDeg, p.track_change_m, p.recession_m,
                          p.wheel_rate_N_per_m, p.roll_centre_height_m});
      for (const auto& p : pts)
        if (p.travel_m == 0.0)
          res.summary["kinematics_at_rest"][axle] = {{"camber_deg", p.camber_rad / kDeg},
                                                      {"wheel_rate_N_per_m", p.wheel_rate_N_per_m},
                                                      {"roll_centre_height_m", p.roll_centre_height_m}};
      res.tables.push_back({"kinematics_" + axle, t});
    }
    return res;
  }

 private:
  double range_, step_;
};

std::vector<FieldInfo> concat(std::vector<FieldInfo> a, const std::vector<FieldInfo>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::vector<FieldInfo> withVehicleKeys(std::vector<FieldInfo> f) {
  const auto keys = HandlingSetup::fields().describe();
  f.insert(f.end(), keys.begin(), keys.end());
  return f;
}
}  // namespace

void registerLimitMapAnalysis(PluginRegistry& registry);  // limit_map_analysis.cpp

void registerHandlingAnalyses(PluginRegistry& registry) {
  registerLimitMapAnalysis(registry);
  registry.addAnalysis(
      "iso4138_constant_radius", [](const ParamReader& r) { return std::make_unique<ConstantRadiusAnalysis>(r); },
      {"ISO 4138 steady-state circular driving, constant radius: steady-state solves (steering angle unknown, U = r R) "
       "continued in speed to the limit; table iso4138.csv",
       withVehicleKeys(ConstantRadiusSettings::fields().describe())});
  registry.addAnalysis(
      "iso7401", [](const ParamReader& r) { return std::make_unique<Iso7401Analysis>(r); },
      {"ISO 7401 step steer (simulation) and frequency response (linearisation about straight running); tables "
       "step_steer.csv, frequency_response.csv",
       withVehicleKeys(concat(StepSteerSettings::fields().describe(),
                              FrequencyKeys::fields().describe()))});
  registry.addAnalysis(
      "sine_with_dwell", [](const ParamReader& r) { return std::make_unique<SineWithDwellAnalysis>(r); },
      {"FMVSS 126 sine with dwell: A at 0.3 g (steady state), 0.7 Hz sine with 500 ms dwell from 1.5 A; yaw-rate "
       "ratios and lateral displacement against the limits; table sine_with_dwell.csv",
       withVehicleKeys(SineWithDwellSettings::fields().describe())});
  registry.addAnalysis(
      "iso3888_2", [](const ParamReader& r) { return std::make_unique<Iso3888Analysis>(r); },
      {"ISO 3888-2 double lane change (obstacle avoidance): the cone layout from the vehicle width, the scene run "
       "closed loop (its path_control plugin follows the lane centres), cone strikes of the body outline, the highest "
       "passing entry speed by bisection; tables iso3888_runs, iso3888_cones, iso3888_best(_corners), "
       "iso3888_fail(_corners)",
       concat(Iso3888Keys::fields().describe(), Iso3888Settings::fields().describe())});
  registry.addAnalysis(
      "vehicle_report", [](const ParamReader& r) { return std::make_unique<VehicleReportAnalysis>(r); },
      {"static corner/axle loads and heights (equilibrium solver) and suspension kinematics over wheel travel "
       "(camber, toe, track change, recession, wheel rate, roll centre); tables kinematics_<axle>.csv",
       TravelKeys::fields().describe()});
}

}  // namespace vdyn
