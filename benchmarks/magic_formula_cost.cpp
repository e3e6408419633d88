// Cost of one tire evaluation, Magic Formula against Gim, measured in one run:
// TireModel::calcForces of the magic_formula kind (combined slip, on
// vehicles/data/tires/pac2002_185_80R14.tir) and of the Gim tire (App. A's
// Table A.4 parameters), on the same grid of load, slip ratio, slip angle and
// camber (the inputs change every call); ns per call in CPU time
// (std::clock), medians of --repeats passes, and their ratio. A program, not
// a test.
//   build/bin/magic_formula_cost [--tire NAME] [--calls N] [--repeats R]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "bench_util.h"
#include "vdyn/core/error.h"
#include "vdyn/core/params.h"
#include "vdyn/magic_formula/magic_formula_tire.h"
#include "vdyn/tire/tire_force.h"

namespace {
/// Median ns per calcForces call of `m` over `grid`.
double nsPerCall(const vdyn::TireModel& m, const std::vector<vdyn::ContactKinematics>& grid, long calls, int repeats,
                 double& sink) {
  std::vector<double> ns;
  for (int r = 0; r < repeats; ++r) {
    const std::clock_t t0 = std::clock();
    for (long i = 0; i < calls; ++i) {
      const vdyn::TireForces f = m.calcForces(grid[static_cast<std::size_t>(i) % grid.size()]);
      sink += f.fx_N + f.fy_N + f.mz_N_m + f.mx_N_m + f.my_N_m;
    }
    ns.push_back(1e9 * double(std::clock() - t0) / CLOCKS_PER_SEC / double(calls));
  }
  return vdyn::bench::median(ns);
}

/// Kinematics at load fz, slip ratio kappa, tan(alpha) ta, camber g, 25 m/s, for model m.
std::vector<vdyn::ContactKinematics> gridFor(const vdyn::TireModel& m) {
  std::vector<vdyn::ContactKinematics> grid;
  const double vx = 25.0;
  for (double fz : {2000.0, 3800.0, 5500.0})
    for (double kappa : {-0.2, -0.03, 0.0, 0.02, 0.1})
      for (double ta : {-0.15, -0.02, 0.0, 0.01, 0.08})
        for (double g : {-0.03, 0.0, 0.02}) {
          vdyn::ContactKinematics k;
          k.deflection_m = vdyn::calcStaticDeflection(m, fz);
          k.vx_m_s = vx;
          k.vy_m_s = vx * ta;
          k.spin_rad_s = vx * (1 + kappa) / m.calcRollingRadius(k.deflection_m);
          k.camber_rad = g;
          grid.push_back(k);
        }
  return grid;
}
}  // namespace

int main(int argc, char** argv) {
  using namespace vdyn;
  std::string tire = "tires/pac2002_185_80R14.tir";
  long calls = 2000000;
  int repeats = 5;
  for (int i = 1; i < argc; i += 2) {
    const std::string opt = argv[i];
    if (i + 1 >= argc) {
      std::fprintf(stderr, "error: option '%s' needs a value\n", opt.c_str());
      return 1;
    }
    if (opt == "--tire") tire = argv[i + 1];
    else if (opt == "--calls") calls = std::atol(argv[i + 1]);
    else if (opt == "--repeats") repeats = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "error: unknown option '%s'; known: --tire, --calls, --repeats\n", opt.c_str());
      return 1;
    }
  }
  if (calls <= 0 || repeats <= 0) {
    std::fprintf(stderr, "error: --calls and --repeats must be positive\n");
    return 1;
  }
  try {
    MagicFormulaTireParams mp;
    mp.file = tire;
    const auto mf = MagicFormulaTire::fromParams(mp, WheelSide::Left);
    const GimTire gim(BrushTireParams::fromParams(ParamReader::fromFile("appendix_a.json").child("tire").child("params")));
    double sink = 0;
    const double tMf = nsPerCall(*mf, gridFor(*mf), calls, repeats, sink);
    const double tGim = nsPerCall(gim, gridFor(gim), calls, repeats, sink);
    std::printf("magic_formula_cost: %ld calls x %d repeats, medians, CPU: magic_formula (%s) %.1f ns per call, "
                "gim (appendix_a.json) %.1f ns per call, ratio %.2f  [checksum %.6g]\n",
                calls, repeats, tire.c_str(), tMf, tGim, tMf / tGim, sink);
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
