// Checks the trailing-arm coast's summary: the degrees of freedom the
// templates give (chassis 6, front corners 1 each with the steering held, rear
// arms 1 each, four wheel spins: 14), the tires carrying the weight once the
// corners have settled (to `tolerance`, relative), and equal left and right
// rear loads. Usage: check_coast SUMMARY.json TOLERANCE
#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: check_coast SUMMARY.json TOLERANCE\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "check_coast: %s: cannot open\n", argv[1]);
    return 1;
  }
  const nlohmann::json s = nlohmann::json::parse(in);
  const double tol = std::atof(argv[2]);
  const int dof = s.at("vehicle").at("dof").get<int>();
  const double weight = s.at("vehicle").at("total_mass_kg").get<double>() * 9.81;
  const nlohmann::json& f = s.at("final");
  double load = 0;
  for (const char* c : {"rf", "lf", "rr", "lr"}) load += f.at(std::string("tire_") + c + ".Fz_N").get<double>();
  const double rr = f.at("tire_rr.Fz_N").get<double>(), lr = f.at("tire_lr.Fz_N").get<double>();
  std::printf("trailing arm: dof %d, tire loads %.2f N against weight %.2f N (%.2e), rear %.2f / %.2f N\n", dof, load,
              weight, std::abs(load - weight) / weight, rr, lr);
  const bool ok = dof == 14 && std::abs(load - weight) < tol * weight && std::abs(rr - lr) < tol * rr &&
                  s.at("vehicle").at("suspensions").at("rear") == "trailing_arm";
  return ok ? 0 : 1;
}
