// vdyn tire TIRE_DATA: any registered tire kind (gim, fiala, linear,
// magic_formula, a --plugin library's) on its own, in steady state: forces and
// moments at a grid of load, slip angle, slip ratio and camber, written as CSV
// with the plots Fy-alpha, Mz-alpha, Fx-kappa and the friction ellipse (Fy
// against Fx). TIRE_DATA is a .tir property file (kind magic_formula) or a JSON
// file with a "tire" block {"plugin": KIND, "params": {...}} (a vehicle data
// file such as appendix_a.json).
//
// Steady state: the deflection carries the load on the radial spring
// (calcStaticDeflection), the contact moves at vx along its heading, Vy = vx
// tan(alpha), the wheel spins at vx (1 + kappa) / Re: kappa = (Omega Re - Vx) /
// |Vx| > 0 driving, alpha > 0 with the patch sliding to the left (+y_C), so Fy
// < 0 there (tire_model.h). Relaxation states are not used (steady slips).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "command.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/plot.h"
#include "vdyn/tire/tire_force.h"

namespace vdyn::cli {

namespace {
const double kDeg = M_PI / 180.0;

/// "a,b,c" -> numbers (times `scale`); the option is named in errors.
std::vector<double> numberList(const std::string& text, const std::string& option, double scale) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(x))
      throw Error("--" + option + ": expected comma-separated numbers, got '" + text + "'");
    v.push_back(x * scale);
  }
  if (v.empty()) throw Error("--" + option + ": no value given");
  return v;
}

/// Values lo..hi in n points.
std::vector<double> range(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(lo + (hi - lo) * i / (n - 1));
  return v;
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
}  // namespace

int tireCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("tire-data", po::value<std::string>(), ".tir file or JSON file with a \"tire\" block")(
      "fz", po::value<std::string>()->default_value("2000,4000,6000"), "normal loads, N (comma-separated)")(
      "alpha", po::value<std::string>(), "slip angles of the grid, deg (default -15..15 in 1 deg steps)")(
      "kappa", po::value<std::string>(), "slip ratios of the grid (default -1..1 in steps of 0.05)")(
      "gamma", po::value<std::string>()->default_value("0"), "camber angles, deg (> 0 top toward +y_C)")(
      "vx", po::value<double>()->default_value(16.7), "forward speed of the wheel centre, m/s")(
      "out", po::value<std::string>(), "output folder (default results/tire_<name>)")(
      "no-plots", "write no PNG plots");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("tire"), args, opts, {"tire-data"}, vm)) return 0;
  if (!vm.count("tire-data")) throw Error("TIRE_DATA is required (a .tir file or a JSON file with a \"tire\" block)");
  const std::string data = vm["tire-data"].as<std::string>();
  const PluginRegistry& registry = registryWithPlugins(vm);

  // The tire as a vehicle would add it: its kind's factory reads the params.
  const SteadyTire tire = SteadyTire::fromData(data, registry);
  const TireModel& model = *tire.model;

  const std::vector<double> loads = numberList(vm["fz"].as<std::string>(), "fz", 1.0);
  for (double fz : loads)
    if (!(fz > 0)) throw Error("--fz: loads must be > 0 N, got " + fmt(fz));
  const std::vector<double> alphas =
      vm.count("alpha") ? numberList(vm["alpha"].as<std::string>(), "alpha", kDeg) : range(-15 * kDeg, 15 * kDeg, 31);
  const std::vector<double> kappas =
      vm.count("kappa") ? numberList(vm["kappa"].as<std::string>(), "kappa", 1.0) : range(-1.0, 1.0, 41);
  const std::vector<double> gammas = numberList(vm["gamma"].as<std::string>(), "gamma", kDeg);
  const double vx = vm["vx"].as<double>();
  if (!(vx > 0) || !std::isfinite(vx)) throw Error("--vx: must be > 0 m/s, got " + fmt(vx));
  std::string name = data.substr(data.find_last_of('/') + 1);
  const std::string out = vm.count("out") ? vm["out"].as<std::string>() : "results/tire_" + name;
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw Error("--out: cannot create '" + out + "': " + ec.message());

  const std::vector<std::string> cols = {"Fz_load_N", "alpha_rad", "kappa", "gamma_rad", "Fx_N", "Fy_N",
                                         "Fz_N", "Mx_N_m", "My_N_m", "Mz_N_m"};
  auto row = [&](double fz, double a, double k, double g) {
    const TireForces f = tire.calcForces(fz, a, k, g, vx);
    return std::vector<double>{fz, a, k, g, f.fx_N, f.fy_N, f.fz_N, f.mx_N_m, f.my_N_m, f.mz_N_m};
  };
  // The whole grid, long format (grid.csv; not plotted).
  Table grid{cols, {}};
  for (double fz : loads)
    for (double g : gammas)
      for (double a : alphas)
        for (double k : kappas) grid.rows.push_back(row(fz, a, k, g));
  grid.writeCsv(out + "/grid.csv");
  std::vector<std::pair<std::string, Table>> tables;
  // Curves for the plots: pure lateral and longitudinal slip per load (first
  // camber), and combined slip at the middle load for a few slip angles.
  std::vector<PlotSpec> plots;
  const std::string what = tire.kind + " (" + name + ")";
  PlotSpec fy{"Fy_alpha", "Lateral force, pure slip: " + what, "slip angle alpha (rad)", "Fy (N)", {}};
  PlotSpec mz{"Mz_alpha", "Aligning moment, pure slip: " + what, "slip angle alpha (rad)", "Mz (N m)", {}};
  PlotSpec fx{"Fx_kappa", "Longitudinal force, pure slip: " + what, "slip ratio kappa (1)", "Fx (N)", {}};
  PlotSpec ellipse{"friction_ellipse", "Combined slip at Fz = " + fmt(loads[loads.size() / 2]) + " N: " + what,
                   "Fx (N)", "Fy (N)", {}};
  ellipse.equal_axes = true;
  for (std::size_t i = 0; i < loads.size(); ++i) {
    Table lat{cols, {}}, lon{cols, {}};
    for (double a : range(-15 * kDeg, 15 * kDeg, 121)) lat.rows.push_back(row(loads[i], a, 0.0, gammas[0]));
    for (double k : range(-1.0, 1.0, 201)) lon.rows.push_back(row(loads[i], 0.0, k, gammas[0]));
    const std::string label = "Fz = " + fmt(loads[i]) + " N";
    tables.push_back({"lateral_" + std::to_string(i), lat});
    tables.push_back({"longitudinal_" + std::to_string(i), lon});
    fy.series.push_back({"lateral_" + std::to_string(i), "alpha_rad", "Fy_N", label});
    mz.series.push_back({"lateral_" + std::to_string(i), "alpha_rad", "Mz_N_m", label});
    fx.series.push_back({"longitudinal_" + std::to_string(i), "kappa", "Fx_N", label});
  }
  const double fzMid = loads[loads.size() / 2];
  int j = 0;
  for (double aDeg : {1.0, 2.0, 4.0, 8.0}) {
    Table c{cols, {}};
    for (double k : range(-1.0, 1.0, 201)) c.rows.push_back(row(fzMid, aDeg * kDeg, k, gammas[0]));
    tables.push_back({"combined_" + std::to_string(j), c});
    ellipse.series.push_back({"combined_" + std::to_string(j), "Fx_N", "Fy_N", "alpha = " + fmt(aDeg) + " deg"});
    ++j;
  }
  plots = {fy, mz, fx, ellipse};
  for (const auto& [n, t] : tables) t.writeCsv(out + "/" + n + ".csv");
  Json summary = {{"tire", tire.kind}, {"data", data}, {"vx_m_s", vx}, {"loads_N", loads},
                  {"grid_points", grid.rows.size()}, {"unloaded_radius_m", model.vertical().unloaded_radius_m},
                  {"radial_stiffness_N_per_m", model.vertical().radial_stiffness_N_per_m}};
  if (!vm.count("no-plots")) summary["plots"] = renderPlots(out, tables, plots);
  writeFileAtomic(out + "/summary.json", summary.dump(2) + "\n");
  std::printf("vdyn tire: %s: %zu grid points (grid.csv), %zu curves: %s/summary.json\n", what.c_str(),
              grid.rows.size(), tables.size(), out.c_str());
  return 0;
}

}  // namespace vdyn::cli
