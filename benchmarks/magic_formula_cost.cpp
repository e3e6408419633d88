// Cost of one Magic Formula evaluation (calcMagicFormula, combined slip, on
// vehicles/data/tires/pac2002_185_80R14.tir): ns per call in CPU time
// (std::clock), median of --repeats passes over a grid of load, slip ratio,
// slip angle and camber (the inputs change every call). A program, not a test.
//   build/bin/magic_formula_cost [--tire NAME] [--calls N] [--repeats R]
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "bench_util.h"
#include "vdyn/core/error.h"
#include "vdyn/core/params.h"
#include "vdyn/magic_formula/magic_formula.h"

int main(int argc, char** argv) {
  using namespace vdyn::mf;
  std::string tire = "tires/pac2002_185_80R14.tir";
  long calls = 2000000;
  int repeats = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    if (opt == "--tire") tire = argv[i + 1];
    else if (opt == "--calls") calls = std::atol(argv[i + 1]);
    else if (opt == "--repeats") repeats = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "error: unknown option '%s'; known: --tire, --calls, --repeats\n", opt.c_str());
      return 1;
    }
  }
  try {
    const MagicFormulaCoefficients c = readTirFile(vdyn::resolveDataPath(tire)).coefficients;
    std::vector<MagicFormulaInputs> grid;
    for (double fz : {2000.0, 3800.0, 5500.0})
      for (double k : {-0.2, -0.03, 0.0, 0.02, 0.1})
        for (double ta : {-0.15, -0.02, 0.0, 0.01, 0.08})
          for (double g : {-0.03, 0.0, 0.02}) {
            MagicFormulaInputs in;
            in.fz_N = fz;
            in.kappa = k;
            in.tan_alpha = ta;
            in.gamma_rad = g;
            in.vx_m_s = 25;
            grid.push_back(in);
          }
    std::vector<double> ns;
    double sink = 0;
    for (int r = 0; r < repeats; ++r) {
      const std::clock_t t0 = std::clock();
      for (long i = 0; i < calls; ++i) {
        const MagicFormulaOutputs o = calcMagicFormula(c, grid[static_cast<std::size_t>(i) % grid.size()]);
        sink += o.fx_N + o.fy_N + o.mz_N_m + o.mx_N_m + o.my_N_m;
      }
      ns.push_back(1e9 * double(std::clock() - t0) / CLOCKS_PER_SEC / double(calls));
    }
    std::printf("magic_formula_cost: %s, %ld calls x %d repeats: median %.1f ns per call (CPU)  [checksum %.6g]\n",
                tire.c_str(), calls, repeats, vdyn::bench::median(ns), sink);
  } catch (const vdyn::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
