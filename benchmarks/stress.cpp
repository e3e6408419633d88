// stress: the stress matrix (not a ctest test; see README). Quarter car,
// nonlinear bicycle and App. A 4WS vehicle; steady-slip and relaxation-length
// tires; speeds 0 (standstill, no speed hold), 0.5, 2, 10, 25, 40 m/s; front
// steering 0, 2, 6, 10, 20 deg by a smooth step (4WS rear at a quarter of it);
// the six integrators at 1e-3 and 1e-6; and a rough sine road that lifts the
// quarter car's wheel. Per cell: completed, event (which) or a named failure
// category; NaN check; largest constraint error; error of the final yaw rate
// (quarter car: psi) against a reference run at rk_merson 1e-9; an invariant
// (speed hold: |speed - U| at the end). Prints a tally, writes stress.csv and
// a heat map (stress.png) to results/stress/ (or --out).
//
// Thinning (to stay within ~15 min on 2 cores): the speed x steering grid runs
// at rk_merson 1e-6 for both vehicles and both tires; the twelve integrator
// settings run on three cells per vehicle and tire (2 m/s 10 deg, 10 m/s
// 6 deg, 25 m/s 2 deg) and on the quarter car.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "study.h"
#include "vdyn/core/events.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/simulation.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steering/steering.h"
#include "vdyn/vehicles/bicycle.h"
#include "vdyn/vehicles/fourws.h"
#include "vdyn/vehicles/quarter_car.h"

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

Outcome runCell(const Cell& c, double tEnd, double budget) {
  Outcome o;
  const auto w0 = std::chrono::steady_clock::now();
  const double deg = SimTK::Pi / 180;
  const bool relax = c.tire == "relaxation";
  try {
    SimulationSettings sim;
    sim.t_end_s = tEnd;
    sim.report_interval_s = 0;
    sim.integrator.method = c.integrator;
    sim.integrator.accuracy = c.accuracy;
    sim.wall_time_budget_s = budget;
    std::unique_ptr<QuarterCar> qc;
    std::unique_ptr<Bicycle> bike;
    std::unique_ptr<FourWsVehicle> car;
    const Scene* scene = nullptr;
    SimTK::State s;
    IntegralHandle psi;
    if (c.vehicle == "quarter_car") {
      QuarterCarParams p = QuarterCarParams::fromFile("quarter_car.json");
      p.tire.relaxation_length_longitudinal_m = relax ? 0.25 : 0;
      p.tire.relaxation_length_lateral_m = relax ? 0.5 : 0;
      if (c.road == "rough") {
        p.road.amplitude_m = 0.05;  // 0.05 m at 12 Hz: the tire leaves the road
        p.road.frequency_Hz = 12;
      }
      qc = std::make_unique<QuarterCar>(p);
      psi = qc->updScene().addIntegralOfSquare("chassis.az_m_s2");
      s = qc->makeInitialState(true);
      scene = &qc->getScene();
    } else if (c.vehicle == "bicycle") {
      BicycleParams p = BicycleParams::fromFile("bicycle.json");
      p.tire.relaxation_length_longitudinal_m = relax ? 0.25 : 0;
      p.tire.relaxation_length_lateral_m = relax ? 0.5 : 0;
      bike = std::make_unique<Bicycle>(p);
      bike->addFrontSteering("front_steer", std::make_shared<SmoothStepCommand>(0, c.steer_deg * deg, 0.5, 1.0));
      if (c.speed > 0) bike->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", c.speed));
      s = bike->makeInitialState(c.speed);
      scene = &bike->getScene();
    } else {
      car = std::make_unique<FourWsVehicle>(FourWsParams::fromFile(relax ? "appendix_a_relaxation.json" : "appendix_a.json"));
      car->addAxleSteering("front_steer", true, std::make_shared<SmoothStepCommand>(0, c.steer_deg * deg, 0.5, 1.0));
      car->addAxleSteering("rear_steer", false, std::make_shared<SmoothStepCommand>(0, 0.25 * c.steer_deg * deg, 0.5, 1.0));
      if (c.speed > 0) car->updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", c.speed));
      s = car->makeInitialState(c.speed);
      scene = &car->getScene();
    }
    EventLimits lim;
    lim.stop_on_spin_out = lim.stop_on_rollover = true;
    EventMonitor events(*scene, lim);
    RunSummary run;
    try {
      run = simulate(*scene, s, sim, nullptr, events.callback());
      o.status = events.events().empty() ? "completed" : "event:" + events.events().front().kind;
      if (!events.events().empty()) o.detail = events.events().front().describe();
    } catch (const RunStopped& e) {
      o.status = "event:" + e.event.kind;
      o.detail = e.event.describe();
    }
    o.steps = run.steps;
    o.constraint_error = run.max_constraint_error;
    for (int i = 0; i < s.getNY(); ++i)
      if (!std::isfinite(s.getY()[i])) o.nan = true;
    if (o.status == "completed") {
      o.value = c.vehicle == "quarter_car" ? scene->getIntegral(psi, s) : scene->evalOutput("chassis.yaw_rate_rad_s", s);
      if (!std::isfinite(o.value)) o.nan = true;
      if (c.speed > 0 && c.vehicle != "quarter_car") {
        const double vx = scene->evalOutput("chassis.forward_speed_m_s", s),
                     vy = scene->evalOutput("chassis.lateral_speed_m_s", s);
        o.invariant = std::abs(std::hypot(vx, vy) - c.speed);
      }
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
        "quick", "a few cells only (a smoke run)")("no-plots", "skip the heat map");
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
    if (quick) cells.resize(std::min<std::size_t>(cells.size(), 8));

    // References: rk_merson at 1e-9 for every (vehicle, tire, speed, steer, road).
    std::map<std::string, double> refs;
    auto key = [](const Cell& c) {
      std::ostringstream k;
      k << c.vehicle << '/' << c.tire << '/' << c.speed << '/' << c.steer_deg << '/' << c.road;
      return k.str();
    };
    const auto w0 = std::chrono::steady_clock::now();
    std::string csv = "vehicle,tire,road,speed_m_s,steer_deg,integrator,accuracy,status,nan,steps,"
                      "max_constraint_error,value,error_vs_reference,invariant_speed_error_m_s,wall_s,detail\n";
    std::map<std::string, int> tally;
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
          refs[key(c)] = ro.status == "completed" ? ro.value : NAN;
        }
      }
      Outcome o = runCell(c, tEnd, budget);
      if (refs.count(key(c)) && std::isfinite(o.value) && std::isfinite(refs[key(c)]))
        o.ref_error = std::abs(o.value - refs[key(c)]) / std::max(1e-3, std::abs(refs[key(c)]));
      tally[o.status]++;
      nanCells += o.nan;
      unnamed += o.status == "unnamed";
      hangs += o.wall_s > 2 * budget;
      std::string detail = o.detail;
      for (auto& ch : detail)
        if (ch == ',' || ch == '\n') ch = ';';
      char buf[512];
      std::snprintf(buf, sizeof buf, "%s,%s,%s,%g,%g,%s,%g,%s,%d,%d,%.3g,%.9g,%.3g,%.3g,%.3f,", c.vehicle.c_str(),
                    c.tire.c_str(), c.road.c_str(), c.speed, c.steer_deg, c.integrator.c_str(), c.accuracy,
                    o.status.c_str(), int(o.nan), o.steps, o.constraint_error, o.value, o.ref_error, o.invariant,
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
    std::printf("  wall time %.1f s; output %s\n", wall, out.c_str());
    study::writeJson(out + "/summary.json", {{"cells", cells.size()}, {"tally", tally}, {"nan_cells", nanCells},
                                             {"hangs", hangs}, {"unnamed_failures", unnamed}, {"wall_time_s", wall}});
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
