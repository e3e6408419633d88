// The MPI sweep runner against the serial one, run by ctest under
// `mpirun --oversubscribe -n 3`: the same synthetic sweep (runs differing 10x
// in cost, one failing variation) must give results.csv and results.json equal
// byte for byte to a serial run; a second MPI run resumes from the journal and
// runs nothing. Rank 0 prints what differs and exits 1 on a failure.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "vdyn/core/sweep_mpi.h"

using namespace vdyn;

namespace {
Json synthetic(const SweepDescription&, const Variation& v) {
  const double x = v.find("a.x")->get<double>();
  const int n = v.find("n")->get<int>();
  if (v.find("fail")) throw Error("synthetic failure at a.x = " + formatValue(x));
  double s = 0;
  for (int k = 1; k <= n; ++k) s += std::sin(x * k) / k;
  return {{"y", s}, {"third", x / 3}, {"n", n}};
}

std::string readFile(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}
}  // namespace

int main(int argc, char** argv) {
  MpiSession mpi(&argc, &argv);
  int failures = 0;
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) {
      ++failures;
      std::fprintf(stderr, "test_sweep_mpi: FAILED: %s\n", what.c_str());
    }
  };
  try {
    const SweepDescription d = SweepDescription::fromJson(Json::parse(R"({
      "scene": "none.json",
      "variations": [
        {"grid": [{"key": "a.x", "from": 0.1, "to": 1.3, "count": 9}, {"key": "n", "values": [3000, 30000]}]},
        {"list": [{"a.x": 0.5, "n": 10, "fail": true}]}
      ],
      "collect": ["y", "third", "n"]})"),
                                                          "mpi_test.json:", "");
    // One folder per mpirun: its ranks share their parent (mpirun), concurrent test runs do not
    // (a fixed name let two runs share one journal, and the second resumed the first's rows).
    const std::string dir = std::filesystem::temp_directory_path().string() + "/vdyn_test_sweep_mpi_" +
                            std::to_string(static_cast<long>(getppid()));
    if (mpi.rank() == 0) std::filesystem::remove_all(dir);
    SweepOptions o;
    o.out_dir = dir;
    o.threads = 1;
    const SweepResult r = runSweepMpi(d, synthetic, o);
    const SweepResult again = runSweepMpi(d, synthetic, o);  // resume: nothing left to run
    if (mpi.rank() == 0) {
      SweepOptions serialOptions;  // in memory
      const SweepResult serial = runSweep(d, synthetic, serialOptions);
      check(readFile(dir + "/results.csv") == formatSweepCsv(d, serial.rows), "results.csv differs from serial");
      check(readFile(dir + "/results.json") == formatSweepJson(d, serial.rows), "results.json differs from serial");
      check(r.ran == d.variations.size(), "first MPI run ran " + std::to_string(r.ran));
      check(r.workers == mpi.size(), "workers " + std::to_string(r.workers));
      check(r.failed == 1 && !r.rows.back().ok &&
                r.rows.back().reason == "synthetic failure at a.x = 0.5",
            "the failing variation's row: '" + r.rows.back().reason + "'");
      check(again.ran == 0 && again.resumed == d.variations.size(), "resume ran " + std::to_string(again.ran));
      std::printf("test_sweep_mpi: %d ranks, %zu variations, %s\n", mpi.size(), d.variations.size(),
                  failures ? "FAILED" : "results equal to serial byte for byte; resume ran nothing");
      std::filesystem::remove_all(dir);
    } else {
      check(r.rows.empty(), "a worker rank returned rows");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "test_sweep_mpi (rank %d): error: %s\n", mpi.rank(), e.what());
    MpiSession::abort(1);
  }
  return failures ? 1 : 0;
}
