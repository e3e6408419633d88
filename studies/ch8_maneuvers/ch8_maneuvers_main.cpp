// ch8_maneuvers: the seed's chapter 8 comparison (docs/equations.md "Manoeuvres"): the
// App. A 4WS vehicle at constant speed follows three lane changes and two
// J-turns with the path controller (7.9)-(7.18) on the front wheels, under
// three rear-steer strategies (8.1)-(8.8): 2ws, linear (Kr of the linear
// bicycle) and nonlinear (Kr = C1 + C2 delta_f^2 from a coefficient table).
// Per scenario one figure (trajectories against the reference, front and rear
// steering, Kr, lateral velocity, path error: Figures 8.2-8.17), a CSV per
// run, and summary.json with key "runs". A run that fails is recorded with
// completed = false and its reason; the study then exits 1 after writing all.
// The runs go through the sweep runner (vdyn/core/sweep.h) on --threads threads.
#include "vdyn/core/text.h"
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "path_study.h"
#include "study.h"
#include "vdyn/core/events.h"
#include "vdyn/core/plugin_library.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/simulation.h"
#include "vdyn/core/sweep.h"
#include "vdyn/path_control/path_control.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/rear_steer/rear_steer.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/vehicles/wheeled_vehicle.h"

using namespace vdyn;

namespace {
const double kDeg = 180 / SimTK::Pi;

struct Scenario {
  std::string id, description;
  double speed_m_s = 0, t_end_s = 0;
  double abort_path_error_m = 2.0;
  double path_peak_ay = 0;  ///< U^2 times the reference's largest curvature, m/s^2
  Json path_json, gains_json;
  std::shared_ptr<const ReferencePath> path;
  PathControlParams gains;
  RearSteerParams rear;
};

struct RunResult {
  std::string csv;
  Json summary;
};

/// The closed loop's damping in the turn of a J-turn: the log decrement
/// (calcSwingDecay: from the largest half-swing while they decrease, pairs of
/// extremes closer than 1e-4 deg dropped) of the front angle's half-swings between
/// the circle's entry (the first sample whose chassis point refers to the arc)
/// and 1 s before its exit (the look-ahead sees the exit earlier).
SwingDecay calcTurnDamping(const Scenario& sc, const Recorder& rec) {
  const auto& t = rec.time();
  const auto &x = rec.column("chassis.x_m"), &y = rec.column("chassis.y_m");
  double t0 = -1, t1 = -1;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (sc.path->calcReferencePoint(SimTK::Vec2(x[i], y[i])).curvature_per_m != 0) {
      if (t0 < 0) t0 = t[i];
      t1 = t[i];
    }
  if (t0 < 0) return {};
  return calcSwingDecay(t, rec.column("front_steer.angle_rad"), t0, t1 - 1.0, 1e-4 / kDeg);
}

RunResult runOne(const SceneDescription& base, const Scenario& sc, const std::string& strategyName,
                 const SimulationSettings& baseSim, const std::string& out, bool showProgress) {
  RunResult r;
  r.csv = out + "/" + sc.id + "_" + strategyName + ".csv";
  r.summary = {{"scenario", sc.id}, {"strategy", strategyName}, {"speed_m_s", sc.speed_m_s}};
  std::unique_ptr<EventMonitor> events;
  try {
    // The composition is the scene (scenes/ch8_maneuvers.json: 4WS vehicle,
    // state-driven front and rear steering, path controller, rear-steer law,
    // speed hold) with this scenario and strategy, built as `vdyn run` does;
    // the run loop (abort on losing the path) and the recording are the study's.
    const BuiltScene built = base.withOverrides({{"vehicle.initial_speed_m_s", sc.speed_m_s},
                                                 {"plugins.speed_hold.speed_m_s", sc.speed_m_s},
                                                 {"plugins.path_control.path", sc.path_json},
                                                 {"plugins.path_control.gains", sc.gains_json},
                                                 {"plugins.rear_control.strategy", strategyName},
                                                 {"plugins.rear_control.g1_per_s2", sc.rear.g1_per_s2},
                                                 {"plugins.rear_control.g2_per_s", sc.rear.g2_per_s}})
                                    .build();
    const Scene& scene = built.scene();
    SimTK::State s = built.makeInitialState();
    SimulationSettings sim = baseSim;
    sim.t_end_s = sc.t_end_s;
    Recorder rec(scene,
                 {"chassis.x_m", "chassis.y_m", "chassis.yaw_rad", "chassis.yaw_rate_rad_s",
                  "chassis.lateral_speed_m_s", "chassis.roll_rad", "front_steer.angle_rad", "front_steer.command_rad",
                  "front_steer.rate_rad_s", "front_steer.accel_rad_s2", "front_steer.drift_rad",
                  "rear_steer.angle_rad", "rear_steer.command_rad", "rear_steer.drift_rad", "rear_control.kr",
                  "rear_control.target_rad", "rear_control.tracking_error_rad", "path_control.e1_m",
                  "path_control.e2", "path_control.e3_m", "path_control.e4", "path_control.path_distance_m",
                  "path_control.lateral_acceleration_m_s2", "path_control.feedforward_rad",
                  "path_control.feedforward_target_rad"});
    // A run that has left the path is stopped (an unstable loop would crawl on
    // with ever smaller steps) and recorded as failed, with the event's time.
    EventLimits limits;
    limits.left_path_distance_m = sc.abort_path_error_m;
    limits.stop_on_spin_out = limits.stop_on_rollover = false;  // reported, the run goes on
    events = std::make_unique<EventMonitor>(scene, limits);
    const RunSummary run = simulate(scene, s, sim, &rec,
                                    events->callback(showProgress ? study::progress(sc.id + " " + strategyName, sim.t_end_s)
                                                                  : std::function<void(const SimTK::State&)>()));
    if (showProgress) study::endProgress();
    rec.writeCsv(r.csv);
    if (sc.path->type() == "j_turn") {
      const SwingDecay d = calcTurnDamping(sc, rec);
      Json amps = Json::array();
      for (double a : d.amplitudes) amps.push_back(a * kDeg);
      r.summary["turn_damping"] = {{"method", "log decrement of the front angle's half-swings in the turn, from the largest while they decrease, "
                                               "sub-1e-4-deg pairs dropped (calcSwingDecay)"},
                                   {"half_swings", d.half_swings}, {"half_swings_deg", amps},
                                   {"zeta", d.half_swings >= 2 ? Json(d.zeta) : Json(nullptr)},
                                   {"frequency_hz", d.half_swings >= 2 ? Json(d.frequency_hz) : Json(nullptr)}};
    }
    const study::ErrorStats err = study::calcErrorStats(rec.column("path_control.path_distance_m"));
    const auto& kr = rec.column("rear_control.kr");
    r.summary.update({{"completed", true},
                      {"events", events->toJson()},
                      {"peak_lateral_velocity_m_s", study::maxAbs(rec.column("chassis.lateral_speed_m_s"))},
                      {"max_path_error_m", err.max_abs},
                      {"rms_path_error_m", err.rms},
                      {"peak_front_steer_deg", study::maxAbs(rec.column("front_steer.angle_rad")) * kDeg},
                      {"peak_rear_steer_deg", study::maxAbs(rec.column("rear_steer.angle_rad")) * kDeg},
                      {"kr_min", *std::min_element(kr.begin(), kr.end())},
                      {"kr_max", *std::max_element(kr.begin(), kr.end())},
                      {"peak_roll_deg", study::maxAbs(rec.column("chassis.roll_rad")) * kDeg},
                      {"peak_lateral_acceleration_m_s2",
                       study::maxAbs(rec.column("path_control.lateral_acceleration_m_s2"))},
                      {"max_rear_tracking_error_rad", study::maxAbs(rec.column("rear_control.tracking_error_rad"))},
                      {"max_steer_drift_rad", std::max(study::maxAbs(rec.column("front_steer.drift_rad")),
                                                       study::maxAbs(rec.column("rear_steer.drift_rad")))},
                      {"max_constraint_error", run.max_constraint_error},
                      {"steps", run.steps},
                      {"realizations", run.realizations},
                      {"integrator_choice", run.integrator_choice},
                      {"peak_feedforward_deg", study::maxAbs(rec.column("path_control.feedforward_rad")) * kDeg},
                      {"sim_time_s", run.sim_time_s},
                      {"wall_time_s", run.wall_time_s}});
  } catch (const std::exception& e) {
    if (showProgress) study::endProgress();
    std::string msg = e.what();
    for (auto& c : msg)
      if (c == '\n') c = ' ';
    r.summary.update({{"completed", false}, {"reason", msg}});
    if (events) r.summary["events"] = events->toJson();
    r.csv.clear();
  }
  return r;
}

/// One figure per scenario (Figures 8.2-8.4 and following): trajectories and
/// reference, front and rear steering (deg), Kr, lateral velocity, path error.
void plotScenario(const std::string& png, const Scenario& sc, const std::string& refCsv,
                  const std::vector<std::pair<std::string, std::string>>& runs) {
  OutputFile g(png + ".gp");
  g << "set terminal pngcairo size 1400,1300 font 'sans,10'\nset output '" << png << "'\n"
    << "set datafile separator ','\nset grid\nset key noenhanced\n"
    << "set multiplot layout 3,2 title '" << sc.id << ": " << sc.description << "' noenhanced\n";
  auto panel = [&](const std::string& title, const std::string& xl, const std::string& yl, const std::string& x,
                   const std::string& y, bool ref) {
    g << "set title '" << title << "' noenhanced\nset xlabel '" << xl << "' noenhanced\nset ylabel '" << yl << "' noenhanced\nplot ";
    bool first = true;
    if (ref) {
      g << "'" << refCsv << "' using (column('x_m')):(column('y_m')) with lines lw 3 lc rgb '#bbbbbb' title 'reference'";
      first = false;
    }
    for (const auto& [label, csv] : runs) {
      g << (first ? "" : ", \\\n     ") << "'" << csv << "' using (" << x << "):(" << y << ") with lines lw 2 title '"
        << label << "'";
      first = false;
    }
    g << "\n";
  };
  panel("trajectory of the chassis c.m.", "x (m)", "y (m)", "column('chassis.x_m')", "column('chassis.y_m')", true);
  panel("path error (distance to the reference, + left)", "t (s)", "error (m)", "column('t_s')",
        "column('path_control.path_distance_m')", false);
  panel("front steering angle", "t (s)", "delta_f (deg)", "column('t_s')", "column('front_steer.angle_rad')*180/pi",
        false);
  panel("rear steering angle", "t (s)", "delta_r (deg)", "column('t_s')", "column('rear_steer.angle_rad')*180/pi",
        false);
  panel("steering angle ratio Kr", "t (s)", "Kr", "column('t_s')", "column('rear_control.kr')", false);
  panel("lateral velocity of the chassis (chassis frame)", "t (s)", "v_eta (m/s)", "column('t_s')",
        "column('chassis.lateral_speed_m_s')", false);
  g << "unset multiplot\n";
  g.commit();
  const std::string cmd = "gnuplot '" + png + ".gp' 2> '" + png + ".log'";
  if (std::system(cmd.c_str()) != 0) throw Error("gnuplot failed on '" + png + ".gp' (see " + png + ".log)");
  std::remove((png + ".log").c_str());
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("ch8_maneuvers", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("data", po::value<std::string>()->default_value("ch8_maneuvers.json"), "manoeuvre data file")(
        "kr-table", po::value<std::string>(),
        "Kr coefficient table for the nonlinear strategy (JSON: delta_f_unit deg, fit [{speed_m_s, c1, "
        "c2_per_deg2}]); default: the data file's kr_table")(
        "scenario", po::value<std::string>(), "comma-separated scenario ids to run (default: all)")(
        "strategy", po::value<std::string>(),
        "comma-separated rear_steer_strategy names: the built-ins 2ws, linear, nonlinear, or one a --plugin library "
        "registers (`vdyn list rear_steer_strategy`); default: the three built-ins")(
        "plugin", po::value<std::vector<std::string>>()->composing(),
        "load an out-of-tree plugin library (repeatable; vdyn/core/plugin_library.h), e.g. one that registers a "
        "rear_steer_strategy")(
        "lane-change-length", po::value<std::string>(),
        "how the seed's lane-change distance reads: 'full' (the whole lane change, X_f - X_0; docs/equations.md) or "
        "'half' (each half, h; Figure 8.1 is lost); default: the data file's lane_change_length")(
        "threads", po::value<int>()->default_value(0),
        "worker threads for the runs (0: one per core); the outputs do not depend on it")(
        "feedforward", po::value<std::string>(),
        "path_control's steer feed-forward: linear_bicycle (the scene's) or none (the seed's law (7.17)-(7.18) "
        "alone; docs/path_feedforward.md)")(
        "no-plots", "skip the PNG plots");
    study::addIntegratorOptions(opts);
    const auto vm = study::parse("ch8_maneuvers",
                                 "lane changes and J-turns of the 4WS vehicle under three rear-steer strategies (ch. 8)",
                                 argc, argv, opts);
    PluginRegistry& registry = standardRegistry();
    if (vm.count("plugin"))
      for (const auto& lib : vm["plugin"].as<std::vector<std::string>>()) loadPluginLibrary(lib, registry);
    const ParamReader data = ParamReader::fromFile(vm["data"].as<std::string>());
    const std::string vehicleData = resolveDataPath(data.string("vehicle_data"));
    WheeledVehicleParams::fromFile(vehicleData);  // a bad vehicle file is an error before any run
    const std::string tablePath = vm.count("kr-table") ? vm["kr-table"].as<std::string>() : data.string("kr_table");
    const KrTable table = KrTable::fromFile(tablePath);
    const LinearBicycleParams linear = LinearBicycleParams::fromParams(data.child("linear_bicycle"));
    const RearSteerParams rearDefault = RearSteerParams::fromParams(data.child("rear_steer_gains"));
    SimulationSettings base;
    base.report_interval_s = data.number("report_interval_s");
    base.integrator = IntegratorSettings::fromParams(data.child("integrator"));
    study::applyIntegratorOptions(vm, base.integrator);
    base.integrator.validate();
    std::vector<Override> sceneOverrides = {{"vehicle.data", vehicleData},
                                {"plugins.rear_control.kr_table", resolveDataPath(tablePath)},
                                {"plugins.rear_control.linear_bicycle", data.child("linear_bicycle").json()},
                                {"plugins.path_control.linear_bicycle", data.child("linear_bicycle").json()}};
    if (vm.count("feedforward"))
      sceneOverrides.push_back({"plugins.path_control.feedforward", vm["feedforward"].as<std::string>()});
    const SceneDescription scene = SceneDescription::fromFile("scenes/ch8_maneuvers.json", registry, sceneOverrides);
    std::string feedforward = "none";  // as the scene (and --feedforward) set it
    for (const Json& p : scene.json().at("plugins"))
      if (p.value("name", "") == "path_control") feedforward = p.value("feedforward", feedforward);


    const std::string reading = vm.count("lane-change-length") ? vm["lane-change-length"].as<std::string>()
                                                                 : data.stringOr("lane_change_length", "full");
    if (reading != "full" && reading != "half")
      throw Error("--lane-change-length must be 'full' or 'half', got '" + reading + "'");
    std::vector<Scenario> scenarios;
    for (const ParamReader& r : data.array("scenarios")) {
      Scenario sc;
      sc.id = r.string("id");
      sc.description = r.string("description");
      sc.speed_m_s = study::checkSpeed({r.number("speed_m_s"), r.at("speed_m_s")});
      sc.t_end_s = requirePositive(r.number("t_end_s"), r.at("t_end_s"));
      sc.abort_path_error_m = requirePositive(data.number("abort_path_error_m"), data.at("abort_path_error_m"));
      sc.path_json = r.raw("path");
      if (reading == "half" && sc.path_json.value("type", "") == "lane_change") {
        // The seed's distance is each half: the lane change spans twice it.
        const double length = sc.path_json.at("length_m").get<double>();
        sc.path_json["length_m"] = 2 * length;
        sc.t_end_s += length / sc.speed_m_s;
      }
      sc.path = makeReferencePath(ParamReader::fromJson(sc.path_json, r.at("path")));
      // With the seed's law alone (feedforward "none") a scenario may keep its own
      // gains (gains_feedforward_none: the J-turns' K5 = 30 of before the
      // feed-forward, so that --feedforward none reproduces those runs). Both read.
      const char* gainsKey = "gains";
      PathControlParams::fromParams(r.child("gains"));  // read (and checked) whichever is used
      if (r.has("gains_feedforward_none")) {
        PathControlParams::fromParams(r.child("gains_feedforward_none"));
        if (feedforward == "none") gainsKey = "gains_feedforward_none";
      }
      sc.gains = PathControlParams::fromParams(r.child(gainsKey));
      sc.gains_json = r.child(gainsKey).json();
      for (const PathPoint& pt : sc.path->sample(0, 0, 0.02))
        sc.path_peak_ay = std::max(sc.path_peak_ay, sc.speed_m_s * sc.speed_m_s * std::abs(pt.curvature_per_m));
      sc.rear = r.has("rear_steer_gains") ? RearSteerParams::fromParams(r.child("rear_steer_gains")) : rearDefault;
      study::checkRunTimes({sc.t_end_s, r.at("t_end_s")}, {base.report_interval_s, data.at("report_interval_s")});
      scenarios.push_back(sc);
    }
    data.requireAllKeysRead();
    if (vm.count("scenario")) {
      std::vector<Scenario> chosen;
      for (const auto& id : splitList(vm["scenario"].as<std::string>())) {
        auto it = std::find_if(scenarios.begin(), scenarios.end(), [&](const Scenario& s) { return s.id == id; });
        if (it == scenarios.end()) {
          std::string known;
          for (const auto& s : scenarios) known += (known.empty() ? "" : ", ") + s.id;
          throw Error("--scenario: unknown scenario '" + id + "'; known: " + known);
        }
        chosen.push_back(*it);
      }
      scenarios = chosen;
    }
    // Strategies by name from the registry the scene is built with (a --plugin
    // library's strategies included): the rear_control plugin makes them.
    std::vector<std::string> strategies = rearSteerStrategyNames();
    if (vm.count("strategy")) {
      strategies = splitList(vm["strategy"].as<std::string>());
      std::string known;
      for (const auto& n : registry.knownChoices("rear_steer_strategy")) known += (known.empty() ? "" : ", ") + n;
      for (const auto& st : strategies) {
        if (!registry.hasChoice("rear_steer_strategy", st))
          throw Error("--strategy: unknown rear steer strategy '" + st + "'; registered: " + known +
                      (vm.count("plugin") ? "" : " (more from a library: --plugin PATH)"));
        makeRearSteerStrategy(st, linear, &table, &registry);  // its factory accepts these parameters
      }
    }
    int threads = vm["threads"].as<int>();
    if (threads < 0) throw Error("--threads must be non-negative, got " + std::to_string(threads));
    if (threads == 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    const std::string out = study::outputDir(vm, "ch8_maneuvers");
    const auto wall0 = std::chrono::steady_clock::now();

    // The runs go through the sweep runner (vdyn/core/sweep.h): one variation per
    // (scenario, strategy), handed out one at a time to --threads threads, each
    // run building its own scene and Simbody system; rows come back in variation
    // order, so the outputs do not depend on the number of threads.
    SweepDescription sweep;
    sweep.name = "ch8_maneuvers";
    {
      GridAxis byScenario{{"scenario"}, {}}, byStrategy{{"strategy"}, {}};
      for (const Scenario& sc : scenarios) byScenario.values.push_back({sc.id});
      for (const auto& st : strategies) byStrategy.values.push_back({st});
      sweep.addVariations(makeGridVariations({byScenario, byStrategy}));
    }
    SweepOptions sweepOptions;
    sweepOptions.threads = threads;
    if (threads > 1 && study::interactive()) sweepOptions.progress = sweepProgressPrinter("ch8_maneuvers");
    const SweepResult swept = runSweep(
        sweep,
        [&](const SweepDescription&, const Variation& v) {
          const Scenario& sc = scenarios[v.index / strategies.size()];
          const std::string& st = strategies[v.index % strategies.size()];
          RunResult r = runOne(scene, sc, st, base, out, threads == 1);
          r.summary["path"] = sc.path_json;
          r.summary["path_peak_lateral_acceleration_m_s2"] = sc.path_peak_ay;
          r.summary["gains"] = {{"k1_rad_per_s2_per_m", sc.gains.k1_rad_per_s2_per_m},
                                {"k2_rad_per_s2", sc.gains.k2_rad_per_s2},
                                {"k3_rad_per_s2_per_m", sc.gains.k3_rad_per_s2_per_m},
                                {"k4_rad_per_s2", sc.gains.k4_rad_per_s2},
                                {"k5_per_s", sc.gains.k5_per_s},
                                {"look_ahead_s", sc.gains.look_ahead_s},
                                {"acceleration_lag_s", sc.gains.acceleration_lag_s},
                                {"g1_per_s2", sc.rear.g1_per_s2},
                                {"g2_per_s", sc.rear.g2_per_s}};
          return r.summary;
        },
        sweepOptions);

    Json runs = Json::array();
    int failed = 0;
    std::size_t row = 0;
    for (const Scenario& sc : scenarios) {
      const std::string refCsv = out + "/" + sc.id + "_reference.csv";
      study::writePathCsv(refCsv, *sc.path, sc.speed_m_s * 1.0, sc.speed_m_s * 2.0);
      std::vector<std::pair<std::string, std::string>> csvs;
      for (const auto& st : strategies) {
        const SweepRow& r = swept.rows[row++];
        if (!r.ok) throw Error(sc.id + " " + st + ": " + r.reason);  // not a failed manoeuvre: an I/O error
        if (r.summary["completed"].get<bool>()) {
          csvs.push_back({st, out + "/" + sc.id + "_" + st + ".csv"});
        } else {
          ++failed;
        }
        runs.push_back(r.summary);
      }
      if (!vm.count("no-plots") && !csvs.empty()) plotScenario(out + "/" + sc.id + ".png", sc, refCsv, csvs);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    study::writeJson(out + "/summary.json",
                     {{"runs", runs}, {"feedforward", feedforward}, {"kr_table", tablePath},
                      {"integrator", base.integrator.method},
                      {"accuracy", base.integrator.accuracy}, {"wall_time_s", wall}, {"threads", threads}});

    std::printf("ch8_maneuvers: 4WS vehicle, %s at %g, Kr table %s, feedforward %s\n", base.integrator.method.c_str(),
                base.integrator.accuracy, tablePath.c_str(), feedforward.c_str());
    std::printf("  %-5s %-9s %6s %12s %10s %10s %9s %9s %13s %15s %7s %s\n", "scen", "strategy", "U m/s", "peak v_y m/s",
                "max err m", "rms err m", "front deg", "rear deg", "Kr min..max", "a_y path/car", "wall s",
                "turn zeta (half-swings deg)");
    for (const Json& j : runs) {
      if (!j["completed"].get<bool>()) {
        std::printf("  %-5s %-9s FAILED: %s\n", j["scenario"].get<std::string>().c_str(),
                    j["strategy"].get<std::string>().c_str(), j["reason"].get<std::string>().c_str());
        continue;
      }
      const double me = j["max_path_error_m"].get<double>(), re = j["rms_path_error_m"].get<double>();
      std::string damping;
      if (j.contains("turn_damping")) {
        const Json& d = j["turn_damping"];
        char buf[64];
        if (d["zeta"].is_null()) {
          const Json& a = d["half_swings_deg"];
          if (a.empty()) {
            damping = "no half-swing above 1e-4 deg";
          } else {
            std::snprintf(buf, sizeof buf, "no swing to decay (one half-swing, %.3g deg)", a[0].get<double>());
            damping = buf;
          }
        } else {
          std::snprintf(buf, sizeof buf, "%.3f (", d["zeta"].get<double>());
          damping = buf;
          const Json& a = d["half_swings_deg"];
          for (std::size_t k = 0; k < a.size() && k < 4; ++k) {
            std::snprintf(buf, sizeof buf, "%s%.3g", k ? ", " : "", a[k].get<double>());
            damping += buf;
          }
          damping += a.size() > 4 ? ", ...)" : ")";
        }
      }
      std::printf("  %-5s %-9s %6.1f %12.4f %10.4f %10.4f %9.3f %9.3f %6.3f..%-6.3f %7.2f/%-7.2f %7.2f %s%s\n",
                  j["scenario"].get<std::string>().c_str(), j["strategy"].get<std::string>().c_str(),
                  j["speed_m_s"].get<double>(), j["peak_lateral_velocity_m_s"].get<double>(), me, re,
                  j["peak_front_steer_deg"].get<double>(), j["peak_rear_steer_deg"].get<double>(),
                  j["kr_min"].get<double>(), j["kr_max"].get<double>(),
                  j["path_peak_lateral_acceleration_m_s2"].get<double>(),
                  j["peak_lateral_acceleration_m_s2"].get<double>(), j["wall_time_s"].get<double>(), damping.c_str(),
                  (me <= 0.10 && re <= 0.03) ? "" : "  (above the 0.10 / 0.03 m bar)");
    }
    std::printf("  total wall time %.1f s; output %s\n", wall, out.c_str());
    if (failed) throw Error(std::to_string(failed) + " of " + std::to_string(runs.size()) +
                            " runs failed (see summary.json)");
  });
}
