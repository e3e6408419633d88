// stress: the stress matrix (not a ctest test; see docs/benchmarks.md, "Stress matrix"). It runs scene
// files, as `vdyn run` does, with --set style overrides (scene_file.h) for
// each cell:
//   quarter car   scenes/quarter_car_sine_road.json (the chapter 4 sine road;
//                 "rough": vehicle.overrides.road amplitude 0.05 m at 12 Hz,
//                 which lifts the wheel off the road)
//   bicycle       scenes/bicycle_step_steer.json (nonlinear bicycle, front step)
//   4WS vehicle   scenes/ch3_transient.json (App. A vehicle, front step, rear at
//                 a quarter of the front)
// Overrides per cell: vehicle.overrides.tire.params.relaxation_length_*_m (0
// = steady-slip tires, 0.25 / 0.5 m = relaxation-length tires);
// vehicle.initial_speed_m_s and plugins.speed_hold.speed_m_s = 0.5, 2, 10, 25,
// 40 m/s, or speed 0 = standstill (the speed hold removed from "plugins");
// plugins.front_steer.command.final_rad = 0, 2, 6, 10, 20 deg (and
// plugins.rear_steer.command.final_rad a quarter of it); analysis.integrator
// .method / .accuracy = the six integrators at 1e-3 and 1e-6; analysis.t_end_s;
// outputs = [] (nothing recorded). The run is the transient analysis's
// (runTransient) with an EventMonitor on every step.
// Per cell: completed, event (which) or a named failure category; NaN check;
// largest constraint error; error of the final yaw rate (quarter car: the cost
// psi, 4.46) against a reference run of the same cell at rk_merson 1e-9, and
// that error over the accuracy asked for (does the integrator's error
// estimate bound the error? issue 12 item 4); an invariant (speed hold:
// |speed - U| at the end). Prints a tally, writes stress.csv and a heat map
// (stress.png) to results/stress/ (or --out).
//
// Thinning (to stay within ~15 min on 2 cores): the speed x steering grid runs
// at rk_merson 1e-6 for both vehicles and both tires; the twelve integrator
// settings run on three cells per vehicle and tire (2 m/s 10 deg, 10 m/s
// 6 deg, 25 m/s 2 deg) and on the quarter car; the rough road at rk_merson
// 1e-6. A cell gets --budget-s of wall time (a named failure beyond it).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "study.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/events.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/simulation.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;

namespace {
struct Cell {
  std::string vehicle, tire, integrator;
  double accuracy = 0, speed = 0, steer_deg = 0;
  std::string road = "flat";
};
struct Outcome {
  std::string status;  // completed | event:<kind> | failure:<category> | unnamed
  std::string detail;
  bool nan = false;
  double constraint_error = NAN, value = NAN, ref_error = NAN, invariant = NAN, wall_s = 0;
  int steps = 0;
};

std::string category(const std::string& msg) {
  if (msg.find("max_steps") != std::string::npos) return "step_limit";
  if (msg.find("step size collapsed") != std::string::npos) return "step_collapse";
  if (msg.find("wall-clock budget") != std::string::npos) return "wall_budget";
  if (msg.find("initializing") != std::string::npos) return "initialization";
  if (msg.find("assembl") != std::string::npos || msg.find("equilibrium") != std::string::npos) return "assembly";
  if (msg.find("speed_m_s") != std::string::npos) return "input";
  if (msg.find("failed at t") != std::string::npos || msg.find("stopped early") != std::string::npos)
    return "integrator";
  return "other_named";
}

const char* sceneFile(const std::string& vehicle) {
  if (vehicle == "quarter_car") return "scenes/quarter_car_sine_road.json";
  if (vehicle == "bicycle") return "scenes/bicycle_step_steer.json";
  return "scenes/ch3_transient.json";
}

/// The cell as --set overrides of its scene file.
std::vector<Override> overridesOf(const Cell& c, double tEnd, double budget, const Json& base) {
  const double deg = SimTK::Pi / 180;
  const bool relax = c.tire == "relaxation";
  std::vector<Override> o = {
      {"analysis.t_end_s", tEnd},
      {"analysis.report_interval_s", 0.0},
      {"analysis.integrator.method", c.integrator},
      {"analysis.integrator.accuracy", c.accuracy},
      {"analysis.wall_time_budget_s", budget},
      {"outputs", Json::array()},
      {"vehicle.overrides.tire.params.relaxation_length_longitudinal_m", relax ? 0.25 : 0.0},
      {"vehicle.overrides.tire.params.relaxation_length_lateral_m", relax ? 0.5 : 0.0}};
  if (c.vehicle == "quarter_car") {
    if (c.road == "rough") {
      o.push_back({"vehicle.overrides.road.amplitude_m", 0.05});  // 0.05 m at 12 Hz: the tire leaves the road
      o.push_back({"vehicle.overrides.road.frequency_Hz", 12.0});
    }
    return o;
  }
  o.push_back({"vehicle.initial_speed_m_s", c.speed});
  o.push_back({"plugins.front_steer.command.final_rad", c.steer_deg * deg});
  if (c.vehicle == "fourws") o.push_back({"plugins.rear_steer.command.final_rad", 0.25 * c.steer_deg * deg});
  if (c.speed > 0) {
    o.push_back({"plugins.speed_hold.speed_m_s", c.speed});
  } else {
    // Standstill: no speed hold (a constraint at 0 m/s would hold the chassis).
    Json plugins = Json::array();
    for (const auto& p : base.at("plugins"))
      if (p.value("name", "") != "speed_hold") plugins.push_back(p);
    o.insert(o.begin(), Override{"plugins", plugins});
  }
  return o;
}

Outcome runCell(const Cell& c, double tEnd, double budget) {
  Outcome o;
  const auto w0 = std::chrono::steady_clock::now();
  try {
    const SceneDescription base = SceneDescription::fromFile(sceneFile(c.vehicle), standardRegistry());
    const SceneDescription desc = base.withOverrides(overridesOf(c, tEnd, budget, base.json()));
    BuiltScene built = desc.build();
    TransientSettings ts =
        TransientSettings::fields().read(ParamReader::fromJson(desc.json().at("analysis"), desc.path() + " analysis"));
    const Scene& scene = built.scene();
    ts.events.stop_on_spin_out = ts.events.stop_on_rollover = true;
    TransientRun tr;
    bool finished = false;
    try {
      tr = runTransient(built, ts, {});
      finished = true;
      o.status = tr.events.empty() ? "completed" : "event:" + tr.events.front().kind;
      if (!tr.events.empty()) o.detail = tr.events.front().describe();
    } catch (const RunStopped& e) {
      o.status = "event:" + e.event.kind;
      o.detail = e.event.describe();
    }
    if (!finished) {
      o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
      return o;
    }
    const SimTK::State& s = tr.final_state;
    o.steps = tr.run.steps;
    o.constraint_error = tr.run.max_constraint_error;
    for (int i = 0; i < s.getNY(); ++i)
      if (!std::isfinite(s.getY()[i])) o.nan = true;
    // The value is compared also when a non-stopping event (lift-off) happened:
    // the run went on to the end.
    o.value = c.vehicle == "quarter_car" ? tr.integrals.at(0) : scene.evalOutput("chassis.yaw_rate_rad_s", s);
    if (!std::isfinite(o.value)) o.nan = true;
    if (c.speed > 0 && c.vehicle != "quarter_car") {
      const double vx = scene.evalOutput("chassis.forward_speed_m_s", s),
                   vy = scene.evalOutput("chassis.lateral_speed_m_s", s);
      o.invariant = std::abs(std::hypot(vx, vy) - c.speed);
    }
  } catch (const Error& e) {
    o.status = "failure:" + category(e.what());
    o.detail = e.what();
  } catch (const std::exception& e) {
    o.status = "unnamed";
    o.detail = e.what();
  }
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return o;
}
}  // namespace

int main(int argc, char** argv) {
  return study::run("stress", [&] {
    namespace po = study::po;
    po::options_description opts("Options");
    opts.add_options()("t-end-s", po::value<double>()->default_value(4.0), "simulated time per cell, s")(
        "budget-s", po::value<double>()->default_value(60.0), "wall-clock budget per cell, s (a named failure)")(
        "quick", "every 35th cell only (a smoke run)")("no-plots", "skip the heat map");
    const auto vm = study::parse("stress", "stress matrix: vehicles x tires x speeds x steering x integrators", argc, argv,
                                 opts);
    const double tEnd = requirePositive(vm["t-end-s"].as<double>(), "--t-end-s");
    const double budget = requirePositive(vm["budget-s"].as<double>(), "--budget-s");
    const std::string out = study::outputDir(vm, "stress");
    const bool quick = vm.count("quick") > 0;

    std::vector<Cell> cells;
    const std::vector<std::pair<std::string, double>> integrators = [&] {
      std::vector<std::pair<std::string, double>> v;
      for (const auto& n : integratorNames())
        for (double a : {1e-3, 1e-6}) v.push_back({n, a});
      return v;
    }();
    for (const std::string tire : {"steady_slip", "relaxation"}) {
      for (const auto& [m, a] : integrators) cells.push_back({"quarter_car", tire, m, a, 0, 0});
      cells.push_back({"quarter_car", tire, "rk_merson", 1e-6, 0, 0, "rough"});
      for (const std::string veh : {"bicycle", "fourws"}) {
        for (double U : {0.0, 0.5, 2.0, 10.0, 25.0, 40.0})
          for (double d : {0.0, 2.0, 6.0, 10.0, 20.0}) cells.push_back({veh, tire, "rk_merson", 1e-6, U, d});
        for (auto [U, d] : std::vector<std::pair<double, double>>{{2, 10}, {10, 6}, {25, 2}})
          for (const auto& [m, a] : integrators)
            if (!(m == "rk_merson" && a == 1e-6)) cells.push_back({veh, tire, m, a, U, d});
      }
    }
    if (quick) {  // every 35th cell: all three vehicles, both tires, standstill and moving
      std::vector<Cell> few;
      for (std::size_t i = 0; i < cells.size(); i += 35) few.push_back(cells[i]);
      cells = few;
    }

    // References: rk_merson at 1e-9 for every (vehicle, tire, speed, steer, road).
    std::map<std::string, double> refs;
    auto key = [](const Cell& c) {
      std::ostringstream k;
      k << c.vehicle << '/' << c.tire << '/' << c.speed << '/' << c.steer_deg << '/' << c.road;
      return k.str();
    };
    const auto w0 = std::chrono::steady_clock::now();
    std::string csv = "vehicle,tire,road,speed_m_s,steer_deg,integrator,accuracy,status,nan,steps,"
                      "max_constraint_error,value,error_vs_reference,error_over_accuracy,invariant_speed_error_m_s,wall_s,detail\n";
    std::map<std::string, int> tally;
    // Per integrator and accuracy: the largest error against the reference
    // over the accuracy asked for, and the cell where it happened.
    std::map<std::string, std::pair<double, std::string>> worst;
    int nanCells = 0, unnamed = 0, hangs = 0;
    std::printf("stress: %zu cells, %.3g s each (budget %.3g s wall)\n", cells.size(), tEnd, budget);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const Cell& c = cells[i];
      if (c.integrator != "rk_merson" || c.accuracy != 1e-6) {
        // the integrator sweep cells need a reference
        if (!refs.count(key(c))) {
          Cell r = c;
          r.integrator = "rk_merson";
          r.accuracy = 1e-9;
          const Outcome ro = runCell(r, tEnd, budget);
          refs[key(c)] = ro.value;  // NaN unless the reference ran to the end
        }
      }
      Outcome o = runCell(c, tEnd, budget);
      if (refs.count(key(c)) && std::isfinite(o.value) && std::isfinite(refs[key(c)]))
        o.ref_error = std::abs(o.value - refs[key(c)]) / std::max(1e-3, std::abs(refs[key(c)]));
      if (std::isfinite(o.ref_error)) {
        auto& w = worst[c.integrator + " " + formatValue(c.accuracy)];
        if (!(o.ref_error / c.accuracy <= w.first)) w = {o.ref_error / c.accuracy, key(c)};
      }
      tally[o.status]++;
      nanCells += o.nan;
      unnamed += o.status == "unnamed";
      hangs += o.wall_s > 2 * budget;
      std::string detail = o.detail;
      for (auto& ch : detail)
        if (ch == ',' || ch == '\n') ch = ';';
      char buf[512];
      std::snprintf(buf, sizeof buf, "%s,%s,%s,%g,%g,%s,%g,%s,%d,%d,%.3g,%.9g,%.3g,%.3g,%.3g,%.3f,", c.vehicle.c_str(),
                    c.tire.c_str(), c.road.c_str(), c.speed, c.steer_deg, c.integrator.c_str(), c.accuracy,
                    o.status.c_str(), int(o.nan), o.steps, o.constraint_error, o.value, o.ref_error, o.ref_error / c.accuracy, o.invariant,
                    o.wall_s);
      csv += buf + detail.substr(0, 300) + "\n";
      std::fprintf(stderr, "\r  %zu / %zu cells", i + 1, cells.size());
    }
    std::fprintf(stderr, "\n");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    writeFileAtomic(out + "/stress.csv", csv);
    std::printf("  tally:");
    for (const auto& [k, n] : tally) std::printf(" %s %d;", k.c_str(), n);
    std::printf("\n  %d NaN, 0 crashes (the process finished), %d hangs (a cell over twice its budget), %d unnamed failures\n",
                nanCells, hangs, unnamed);
    std::printf("  error against the rk_merson 1e-9 reference over the accuracy asked for, worst cell (vehicle/tire/"
                "speed/steer/road):\n");
    Json worstJson = Json::object();
    for (const auto& [k, w] : worst) {
      std::printf("    %-28s %9.3g  %s\n", k.c_str(), w.first, w.second.c_str());
      worstJson[k] = {{"error_over_accuracy", w.first}, {"cell", w.second}};
    }
    std::printf("  wall time %.1f s; output %s\n", wall, out.c_str());
    study::writeJson(out + "/summary.json", {{"cells", cells.size()}, {"tally", tally}, {"nan_cells", nanCells},
                                             {"hangs", hangs}, {"unnamed_failures", unnamed}, {"wall_time_s", wall},
                                             {"worst_error_over_accuracy", worstJson}});
    if (!vm.count("no-plots")) {
      // Heat map: one row per (vehicle, tire, integrator), one column per (speed, steer); colour = status.
      std::string dat = "# row col code\n";
      std::map<std::string, int> rows, cols;
      std::istringstream in(csv);
      std::string line;
      std::getline(in, line);
      std::string rowLabels, colLabels;
      while (std::getline(in, line)) {
        std::vector<std::string> f;
        std::stringstream ls(line);
        std::string x;
        while (std::getline(ls, x, ',')) f.push_back(x);
        const std::string rk = f[0] + " " + f[1] + " " + f[2] + " " + f[5] + " " + f[6];
        const std::string ck = f[3] + "m/s " + f[4] + "deg";
        if (!rows.count(rk)) rows[rk] = int(rows.size());
        if (!cols.count(ck)) cols[ck] = int(cols.size());
        const std::string& st = f[7];
        const int code = st == "completed" ? 0 : st.rfind("event", 0) == 0 ? 1 : st.rfind("failure", 0) == 0 ? 2 : 3;
        dat += std::to_string(cols[ck]) + " " + std::to_string(rows[rk]) + " " + std::to_string(code) + "\n";
      }
      writeFileAtomic(out + "/stress.dat", dat);
      std::string gp = "set terminal pngcairo size 1600,1400 font 'sans,8' noenhanced\nset output '" + out + "/stress.png'\n"
                       "set title 'stress matrix: green completed, orange event, red named failure, black unnamed'\n"
                       "set palette defined (0 'forest-green', 1 'orange', 2 'red', 3 'black')\nset cbrange [0:3]\n"
                       "unset colorbox\nset xtics rotate by 90 font ',7'\nset ytics font ',7'\n";
      gp += "set xtics (";
      bool first = true;
      for (const auto& [k, i] : cols) gp += std::string(first ? "" : ", ") + "\"" + k + "\" " + std::to_string(i), first = false;
      gp += ")\nset ytics (";
      first = true;
      for (const auto& [k, i] : rows) gp += std::string(first ? "" : ", ") + "\"" + k + "\" " + std::to_string(i), first = false;
      gp += ")\nplot '" + out + "/stress.dat' using 1:2:3 with points pt 5 ps 1.6 palette notitle\n";
      writeFileAtomic(out + "/stress.gp", gp);
      if (std::system(("gnuplot '" + out + "/stress.gp'").c_str()) != 0) throw Error("gnuplot failed on stress.gp");
    }
    if (nanCells || unnamed || hangs) throw Error("stress: NaN, unnamed failures or hangs (see stress.csv)");
  });
}
