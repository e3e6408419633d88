// Checks a coast-down run of the quadratic drag (examples/aero_drag/coast_down.json;
// docs/equations.md, "Aerodynamic drag"):
//  - speed: v(t) against v0 / (1 + c v0 t / m_e), with c = rho Cd A / 2 read from
//    the scene's plugin and m_e = 2 T(0) / v0^2 (vehicle mass plus wheel spin
//    inertia over rolling radius squared, from the kinetic energy T);
//  - energy: the drag's work against the change of mechanical energy.
// Usage: check_coast_down SCENE.json RUN_DIR MAX_SPEED_ERROR MAX_ENERGY_ERROR
// (relative errors). Prints both errors; exit 1 if one exceeds its bound.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "quadratic_drag.h"
#include "vdyn/core/error.h"
#include "vdyn/core/params.h"

namespace {
/// history.csv: a header row of names, then rows of numbers.
std::map<std::string, std::vector<double>> readCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw vdyn::Error("cannot open '" + path + "'");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string n; std::getline(header, n, ',');) names.push_back(n);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t i = 0; i < names.size() && std::getline(row, cell, ','); ++i)
      cols[names[i]].push_back(std::strtod(cell.c_str(), nullptr));
  }
  return cols;
}
const std::vector<double>& column(const std::map<std::string, std::vector<double>>& c, const std::string& name) {
  auto it = c.find(name);
  if (it == c.end() || it->second.empty()) throw vdyn::Error("history.csv: no column '" + name + "'");
  return it->second;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: check_coast_down SCENE.json RUN_DIR MAX_SPEED_ERROR MAX_ENERGY_ERROR\n");
    return 2;
  }
  try {
    // The drag's parameters as the scene gives them (the same reader as the plugin).
    const vdyn::ParamReader scene = vdyn::ParamReader::fromFile(argv[1]);
    double c = -1;
    std::string name;
    for (const vdyn::ParamReader& p : scene.array("plugins"))
      if (p.string("type") == "quadratic_drag") {
        c = vdyn_example::QuadraticDragParams::fromParams(p).coefficient_kg_per_m();
        name = p.string("name");
      }
    if (c < 0) throw vdyn::Error(std::string(argv[1]) + ": no quadratic_drag plugin");
    const auto h = readCsv(std::string(argv[2]) + "/history.csv");
    const auto& t = column(h, "t_s");
    const auto& v = column(h, "chassis.forward_speed_m_s");
    const auto& W = column(h, name + ".work_J");
    const auto& E = column(h, name + ".mechanical_energy_J");
    const auto& T = column(h, name + ".kinetic_energy_J");
    const double v0 = v.front(), me = 2 * T.front() / (v0 * v0);
    double speedError = 0;
    for (std::size_t i = 0; i < t.size(); ++i)
      speedError = std::max(speedError, std::abs(v[i] - v0 / (1 + c * v0 * t[i] / me)) / v[i]);
    const double dE = E.back() - E.front(), energyError = std::abs(dE - W.back()) / std::abs(W.back());
    const double maxSpeed = std::atof(argv[3]), maxEnergy = std::atof(argv[4]);
    std::printf("coast-down: c = %.4f kg/m, m_e = %.2f kg, v %.4f -> %.4f m/s over %.1f s\n", c, me, v0, v.back(),
                t.back());
    std::printf("coast-down: max |v - v0 / (1 + c v0 t / m_e)| / v = %.2e (bound %.0e)\n", speedError, maxSpeed);
    std::printf("coast-down: drag work %.2f J, mechanical energy change %.2f J, relative difference %.2e (bound %.0e)\n",
                W.back(), dE, energyError, maxEnergy);
    return speedError <= maxSpeed && energyError <= maxEnergy ? 0 : 1;
  } catch (const vdyn::Error& e) {
    std::fprintf(stderr, "check_coast_down: error: %s\n", e.what());
    return 1;
  }
}
