// Scaling of the sweep runners (vdyn/core/sweep.h, sweep_mpi.h): wall time,
// CPU time and speed-up of one sweep on 1 and 2 threads and 1 and 2 MPI
// processes, the runner's own overhead per run, and the serial fraction that
// predicts the speed-up on N cores (Amdahl: S(N) = 1 / (f + (1 - f) / N)).
//
// Workload: the chapter 3 transient scene (vehicles/data/scenes/ch3_transient.json,
// the 4WS vehicle at 10 m/s with a steer step) run by the scene runner
// (runScene, as `vdyn sweep` runs it) with analysis.t_end_s from --t-min-s to
// --t-max-s over --runs variations, so runs differ ~10x in cost (the dynamic
// balancing case). Overhead: the same runners on --null-runs variations whose run does
// nothing, so all that is timed is the runner (scheduling, journal lines,
// messages). The MPI configurations re-run this program under
// `mpirun --oversubscribe -n K` (as root it sets OMPI_ALLOW_RUN_AS_ROOT*).
// Every configuration's results.csv must be byte-identical (checked).
//
//   ./build/bin/sweep_scaling                      # table on stdout
//   ./build/bin/sweep_scaling --repeats 5 --runs 16
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "bench_util.h"
#include "study.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/vehicles/standard_registry.h"
#ifdef VDYN_HAVE_MPI
#include "vdyn/core/sweep_mpi.h"
#endif

using namespace vdyn;

namespace {

SweepDescription makeSweep(const std::string& workload, int runs, double tMin, double tMax) {
  SweepDescription d;
  d.name = "sweep_scaling_" + workload;
  d.scene = workload == "ch3" ? "scenes/ch3_transient.json" : "(none)";
  GridAxis ax{{"analysis.t_end_s"}, {}};
  for (int i = 0; i < runs; ++i)
    ax.values.push_back({runs == 1 ? tMin : tMin + (tMax - tMin) * double(i) / double(runs - 1)});
  d.addVariations(makeGridVariations({ax}));
  d.collect = workload == "ch3" ? std::vector<std::string>{"final.chassis.yaw_rate_rad_s",
                                                           "final.chassis.side_slip_rad", "run.steps"}
                                : std::vector<std::string>{"t_end_s"};
  return d;
}

SweepRunFunction makeRun(const std::string& workload) {
  if (workload == "null")
    return [](const SweepDescription&, const Variation& v) { return Json{{"t_end_s", *v.find("analysis.t_end_s")}}; };
  // The scene is loaded once; each run applies its override and builds anew.
  const auto scene = std::make_shared<SceneDescription>(
      SceneDescription::fromFile("scenes/ch3_transient.json", standardRegistry()));
  return [scene](const SweepDescription&, const Variation& v) {
    return runScene(scene->withOverrides({Override{"analysis.t_end_s", *v.find("analysis.t_end_s")}}));
  };
}

std::string readFile(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

double childrenCpu() {
  rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  return ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec + ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
}

double loadAverage() {
  double l = -1;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &l) != 1) l = -1;
    std::fclose(f);
  }
  return l;
}

struct Measured {
  double wall_s = 0;       ///< the sweep's wall time (median over repeats)
  double launch_s = 0;     ///< MPI: mpirun's whole wall time incl. start-up
  double cpu_s = 0;        ///< CPU of all threads / ranks (median)
  double overhead_ms = 0;  ///< runner time per run outside the runs (median)
  double load = 0;         ///< 1-min load average at the start (median)
  int workers = 0;
  std::size_t runs = 0, failed = 0;
  double tail_bound = 0;   ///< threads: sum of run times / longest run (the most any N can give)
  double run_cpu_sum = 0;  ///< threads: CPU time of all runs, s (median): the work W
  double run_cpu_max = 0;  ///< threads: CPU time of the costliest run, s (median)
  std::string csv;
};

struct Config {
  std::string label;  ///< "threads" or "mpi"
  int count = 1;      ///< threads, or MPI processes
  int rank0Threads = 1;  ///< MPI: worker threads on rank 0 (0 = manager only)
};

// Every configuration once per repeat, in turn (c1 c2 c3 c4 c1 c2 ...), so a
// change of the machine's other load affects all configurations alike.
std::vector<Measured> measure(const std::vector<Config>& configs, const std::string& workload, int runs, double tMin,
                              double tMax, int repeats, const std::string& outRoot) {
  struct Samples {
    std::vector<double> wall, launch, cpu, over, load, runCpuSum, runCpuMax;
  };
  std::vector<Samples> samples(configs.size());
  std::vector<Measured> ms(configs.size());
  for (int r = 0; r < repeats; ++r)
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const Config& c = configs[ci];
    Measured& m = ms[ci];
    auto& [wall, launch, cpu, over, load, runCpuSum, runCpuMax] = samples[ci];
    const std::string dir = outRoot + "/" + workload + "_" + c.label + std::to_string(c.count) + "_" +
                            std::to_string(c.rank0Threads);
    std::filesystem::remove_all(dir);
    load.push_back(loadAverage());
    if (c.label == "threads") {
      const SweepDescription d = makeSweep(workload, runs, tMin, tMax);
      SweepOptions o;
      o.threads = c.count;
      o.out_dir = dir;
      const SweepResult res = runSweep(d, makeRun(workload), o);
      wall.push_back(res.wall_s);
      cpu.push_back(res.cpu_s);
      m.workers = res.workers;
      double sum = 0, longest = 0;
      for (const SweepRow& row : res.rows) sum += row.wall_s, longest = std::max(longest, row.wall_s);
      m.tail_bound = longest > 0 ? sum / longest : 0;
      double cpuSum = 0, cpuMax = 0;
      for (const SweepRow& row : res.rows) cpuSum += row.cpu_s, cpuMax = std::max(cpuMax, row.cpu_s);
      runCpuSum.push_back(cpuSum);
      runCpuMax.push_back(cpuMax);
    } else {
      char cmd[4096];
      std::snprintf(cmd, sizeof cmd,
                    "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -n %d "
                    "/proc/%d/exe --child --workload %s --runs %d --t-min-s %.17g --t-max-s %.17g "
                    "--rank0-threads %d --out '%s' > '%s.log' 2>&1",
                    c.count, int(getpid()), workload.c_str(), runs, tMin, tMax, c.rank0Threads, dir.c_str(),
                    dir.c_str());
      // /proc/<pid>/exe of this process: the same binary, whatever the working directory.
      const double cpu0 = childrenCpu();
      const auto t0 = std::chrono::steady_clock::now();
      const int rc = std::system(cmd);
      launch.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      cpu.push_back(childrenCpu() - cpu0);
      if (rc != 0) throw Error("mpirun failed (" + std::to_string(rc) + "): see " + dir + ".log");
      const Json stats = readJsonFile(dir + "/sweep_stats.json");
      wall.push_back(stats["wall_s"].get<double>());
      m.workers = stats["workers"].get<int>();
    }
    const Json stats = readJsonFile(dir + "/sweep_stats.json");
    over.push_back(stats["overhead_ms_per_run"].get<double>());
    m.runs = stats["ran"].get<std::size_t>();
    m.failed = stats["failed"].get<std::size_t>();
    m.csv = readFile(dir + "/results.csv");
  }
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
  Measured& m = ms[ci];
  const auto& [wall, launch, cpu, over, load, runCpuSum, runCpuMax] = samples[ci];
  m.wall_s = bench::median(wall);
  m.launch_s = launch.empty() ? 0 : bench::median(launch);
  m.cpu_s = bench::median(cpu);
  m.overhead_ms = bench::median(over);
  m.load = bench::median(load);
  if (!runCpuSum.empty()) m.run_cpu_sum = bench::median(runCpuSum), m.run_cpu_max = bench::median(runCpuMax);
  }
  return ms;
}

int child(const study::po::variables_map& vm) {
#ifdef VDYN_HAVE_MPI
  int argc = 0;
  char** argv = nullptr;
  MpiSession mpi(&argc, &argv);
  try {
    const std::string workload = vm["workload"].as<std::string>();
    const SweepDescription d =
        makeSweep(workload, vm["runs"].as<int>(), vm["t-min-s"].as<double>(), vm["t-max-s"].as<double>());
    SweepOptions o;
    o.threads = vm["rank0-threads"].as<int>();
    o.out_dir = vm["out"].as<std::string>();
    runSweepMpi(d, makeRun(workload), o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_scaling (rank %d): error: %s\n", mpi.rank(), e.what());
    MpiSession::abort(1);
  }
  return 0;
#else
  (void)vm;
  std::fprintf(stderr, "sweep_scaling: built without MPI\n");
  return 1;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("runs", po::value<int>()->default_value(12), "ch3 runs in the timed sweep")(
      "t-min-s", po::value<double>()->default_value(1.0), "shortest simulated time, s")(
      "t-max-s", po::value<double>()->default_value(10.0), "longest simulated time, s (cost ~ t: 10x spread)")(
      "repeats", po::value<int>()->default_value(3), "repeats of each configuration (medians are shown)")(
      "null-runs", po::value<int>()->default_value(2000), "runs of the empty workload (runner overhead)")(
      "no-mpi", "skip the MPI configurations")("child", "(internal) run as one MPI rank")(
      "workload", po::value<std::string>()->default_value("ch3"), "(internal) ch3 or null")(
      "rank0-threads", po::value<int>()->default_value(1), "(internal) worker threads on MPI rank 0");
  bool isChild = false;
  for (int i = 1; i < argc; ++i) isChild = isChild || std::string(argv[i]) == "--child";
  if (isChild) {
    po::options_description all(opts);
    all.add_options()("out", po::value<std::string>(), "");
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, all), vm);
    return child(vm);
  }
  return study::run("sweep_scaling", [&] {
    const auto vm = study::parse("sweep_scaling", "scaling of the sweep runners: threads and MPI processes", argc, argv,
                                 opts);
    const int runs = vm["runs"].as<int>(), repeats = vm["repeats"].as<int>(), nullRuns = vm["null-runs"].as<int>();
    const double tMin = vm["t-min-s"].as<double>(), tMax = vm["t-max-s"].as<double>();
    if (runs < 2 || repeats < 1 || nullRuns < 1) throw Error("--runs >= 2, --repeats >= 1, --null-runs >= 1");
    const std::string out = study::outputDir(vm, "benchmarks/sweep_scaling");
    bool mpi = false;
#ifdef VDYN_HAVE_MPI
    mpi = !vm.count("no-mpi") && std::system("command -v mpirun > /dev/null 2>&1") == 0;
#endif
    char host[256] = {0};
    gethostname(host, sizeof host - 1);
    std::printf("sweep_scaling: %d ch3 runs (t_end %g..%g s, cost ~ t_end), %d repeats (medians), host %s, %ld cores\n",
                runs, tMin, tMax, repeats, host, sysconf(_SC_NPROCESSORS_ONLN));
    std::printf("  command: %s --runs %d --t-min-s %g --t-max-s %g --repeats %d --null-runs %d%s\n", argv[0], runs,
                tMin, tMax, repeats, nullRuns, mpi ? "" : " --no-mpi");

    std::vector<Config> configs = {{"threads", 1, 1}, {"threads", 2, 1}};
    if (mpi) configs.insert(configs.end(), {{"mpi", 1, 1}, {"mpi", 2, 1}});
    std::vector<Measured> ms;
    ms = measure(configs, "ch3", runs, tMin, tMax, repeats, out);

    std::printf("\n  ch3 sweep            workers   wall s  speed-up   CPU s  CPU/CPU1  CPU/wall  idle+runner ms/run  "
                "load(1 min)  runs\n");
    const double t1 = ms[0].wall_s;
    bool identical = true;
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const Measured& m = ms[i];
      identical = identical && m.csv == ms[0].csv;
      char label[64];
      std::snprintf(label, sizeof label, "%s %d%s", configs[i].label == "mpi" ? "MPI processes" : "threads",
                    configs[i].count, configs[i].label == "mpi" ? "" : "      ");
      std::printf("  %-20s %7d %8.2f %9.2f %7.2f %9.3f %9.2f %19.2f %12.2f %5zu%s\n", label, m.workers, m.wall_s,
                  t1 / m.wall_s, m.cpu_s, m.cpu_s / ms[0].cpu_s, m.cpu_s / m.wall_s, m.overhead_ms, m.load, m.runs,
                  m.failed ? " (failed runs!)" : "");
      if (configs[i].label == "mpi")
        std::printf("  %-20s          (mpirun incl. start-up: %.2f s)\n", "", m.launch_s);
    }
    std::printf("  results.csv byte-identical across all configurations: %s\n", identical ? "yes" : "NO");

    // --- runner overhead: the same runners on runs that do nothing ----------------
    std::vector<Config> nullConfigs = {{"threads", 1, 1}, {"threads", 2, 1}};
    if (mpi) nullConfigs.insert(nullConfigs.end(), {{"mpi", 2, 0}, {"mpi", 2, 1}});
    std::printf("\n  empty runs (%d): runner overhead  wall s   ms/run (wall / runs; MPI manager-only: one message\n"
                "  round trip per run, test-and-sleep waits)\n", nullRuns);
    double serialMsPerRun = 0, mpiMsPerRun = 0;
    const std::vector<Measured> nullMs = measure(nullConfigs, "null", nullRuns, 0, 1, repeats, out);
    for (std::size_t ci = 0; ci < nullConfigs.size(); ++ci) {
      const Config& c = nullConfigs[ci];
      const Measured& m = nullMs[ci];
      const double msPerRun = 1e3 * m.wall_s / double(nullRuns);
      if (c.label == "threads" && c.count == 1) serialMsPerRun = msPerRun;
      if (c.label == "mpi" && c.rank0Threads == 0) mpiMsPerRun = msPerRun;
      std::printf("  %-33s %7.3f %8.4f\n",
                  (c.label == "threads" ? "threads " + std::to_string(c.count)
                                        : "MPI " + std::to_string(c.count) + " processes, rank 0 " +
                                              (c.rank0Threads ? "also runs" : "only manages"))
                      .c_str(),
                  m.wall_s, msPerRun);
    }

    // --- Amdahl -----------------------------------------------------------------
    const double s2 = t1 / ms[1].wall_s;
    const double fSpeedup = std::clamp(2.0 / s2 - 1.0, 0.0, 1.0);
    const double fRunner = serialMsPerRun * 1e-3 * runs / t1;
    std::printf("\n  serial fraction f from the 2-thread speed-up (f = 2/S2 - 1): %.4f\n", fSpeedup);
    std::printf("  serial fraction f of the runner alone (%.4f ms/run x %d runs / %.2f s): %.2e\n", serialMsPerRun,
                runs, t1, fRunner);
    std::printf("  predicted speed-up S(N) = 1 / (f + (1 - f) / N):\n     N");
    for (int n : {2, 4, 8, 16, 64}) std::printf(" %8d", n);
    std::printf("\n  f=%-.4f", fSpeedup);
    for (int n : {2, 4, 8, 16, 64}) std::printf(" %8.2f", 1 / (fSpeedup + (1 - fSpeedup) / n));
    std::printf("\n  f=%.1e", fRunner);
    for (int n : {2, 4, 8, 16, 64}) std::printf(" %8.2f", 1 / (fRunner + (1 - fRunner) / n));
    std::printf("\n  tail bound of this sweep: S <= sum of run times / longest run = %.2f (%d runs, cost ~ t_end)",
                ms[0].tail_bound, runs);
    std::printf("\n  (the runner's own f bounds what the runner costs; the measured f also holds the machine's\n"
                "   other load, memory bandwidth shared by the runs and the tail: the last run alone on a core)\n");

    // --- prediction from CPU times (independent of the machine's other load) ------
    // Work W = CPU time of all runs, t_max = the costliest run (CPU), n runs, o =
    // runner time per run (threads: serial, under the journal lock; MPI: one
    // round trip per run, a latency each worker pays). Greedy hand-out one run
    // at a time (list scheduling, Graham 1969) on N cores finishes within
    //   max(W/N, t_max) <= T_N <= W/N + (1 - 1/N) t_max,  plus n o (threads) or n o / N (MPI).
    const double W = ms[0].run_cpu_sum, tmax = ms[0].run_cpu_max, n = runs;
    std::printf("\n  prediction from CPU times (load-independent): W = %.3f s CPU in %d runs (mean %.1f ms), "
                "longest run %.3f s\n", W, runs, 1e3 * W / n, tmax);
    std::printf("  runner per run o: threads %.4f ms (serial), MPI %.4f ms (round trip per worker)\n", serialMsPerRun,
                mpiMsPerRun);
    std::printf("     N     this sweep: S = W / T_N (Graham bounds)     many runs of this mean cost: S = N / (1 + N f)\n");
    const double fT = serialMsPerRun * 1e-3 / (W / n), fM = mpiMsPerRun * 1e-3 / (W / n);
    for (int N : {1, 2, 4, 8, 16, 64}) {
      const double lo = std::max(W / N, tmax) + n * serialMsPerRun * 1e-3;
      const double hi = W / N + (1 - 1.0 / N) * tmax + n * serialMsPerRun * 1e-3;
      std::printf("  %4d     threads %5.2f .. %5.2f                      threads %6.2f (f %.1e), MPI %6.2f (%.1e)\n",
                  N, W / hi, W / lo, N / (1 + N * fT), fT, N / (1 + fM), fM);
    }
    std::printf("  output: %s\n", out.c_str());
    if (!identical) throw Error("results.csv differs between configurations");
  });
}
