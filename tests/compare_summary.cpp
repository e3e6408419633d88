// compare_summary A.json B.json PATH_A=PATH_B[@TOL] ...
// Checks that each value at PATH_A in A equals the value at PATH_B in B (key
// paths split at '/', array elements by index: "final/chassis.yaw_rate_rad_s",
// "wheel_spin_rad_s/0"). Numbers compare to a relative tolerance TOL (default
// 0: bit-identical), anything else exactly. Prints every comparison; exits 1
// on the first difference's report after printing all, 2 on a usage error.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

using Json = nlohmann::json;

static const Json* at(const Json& j, const std::string& path) {
  const Json* n = &j;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string k = path.substr(start, end - start);
    if (n->is_array()) {
      const std::size_t i = std::stoul(k);
      if (i >= n->size()) return nullptr;
      n = &(*n)[i];
    } else if (n->is_object() && n->contains(k)) {
      n = &(*n)[k];
    } else {
      return nullptr;
    }
    start = end + 1;
  }
  return n;
}

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: compare_summary A.json B.json PATH_A=PATH_B[@TOL] ...\n");
    return 2;
  }
  Json a, b;
  try {
    std::ifstream fa(argv[1]), fb(argv[2]);
    a = Json::parse(fa, nullptr, true, true);
    b = Json::parse(fb, nullptr, true, true);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare_summary: %s\n", e.what());
    return 2;
  }
  int bad = 0;
  for (int i = 3; i < argc; ++i) {
    std::string spec = argv[i];
    double tol = 0;
    if (auto p = spec.find('@'); p != std::string::npos) {
      tol = std::stod(spec.substr(p + 1));
      spec.resize(p);
    }
    const auto eq = spec.find('=');
    const std::string pa = spec.substr(0, eq), pb = eq == std::string::npos ? pa : spec.substr(eq + 1);
    const Json *va = at(a, pa), *vb = at(b, pb);
    if (!va || !vb) {
      std::printf("MISSING %s (%s) / %s (%s)\n", pa.c_str(), va ? "ok" : "absent", pb.c_str(), vb ? "ok" : "absent");
      ++bad;
      continue;
    }
    bool same;
    if (va->is_number() && vb->is_number()) {
      const double x = va->get<double>(), y = vb->get<double>();
      same = tol == 0 ? x == y : std::abs(x - y) <= tol * std::max(std::abs(x), std::abs(y));
      std::printf("%s %s = %.17g, %s = %.17g (rel diff %.3g, tol %g)\n", same ? "ok  " : "DIFF", pa.c_str(), x,
                  pb.c_str(), y, std::abs(x - y) / std::max(std::abs(y), 1e-300), tol);
    } else {
      same = *va == *vb;
      std::printf("%s %s = %s, %s = %s\n", same ? "ok  " : "DIFF", pa.c_str(), va->dump().c_str(), pb.c_str(),
                  vb->dump().c_str());
    }
    if (!same) ++bad;
  }
  return bad ? 1 : 0;
}
