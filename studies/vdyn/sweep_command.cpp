// vdyn sweep SWEEP: run a scene over the variations of a sweep file
// (vdyn/core/sweep.h) on threads or MPI processes, and gather one table.
//   vdyn sweep SWEEP [--threads N] [--out DIR] [--fresh] [--retry-failed]
//   mpirun -n N vdyn sweep SWEEP --mpi
// Each run is the scene file with the sweep's "set" and the variation's
// settings applied as --set overrides (scene_file.h), built and run in its
// own Simbody system; its summary JSON gives the collected columns. Results:
// <out>/results.csv and results.json (ordered by variation, identical for any
// number of threads or ranks), runs.jsonl (the journal a resumed sweep skips),
// sweep_stats.json (times), and the sweep file's plots (PNG + .gp script).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "command.h"
#include "vdyn/core/file_io.h"
#include "vdyn/core/interrupt.h"
#include "vdyn/core/key_path.h"
#include "vdyn/core/plot.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#ifdef VDYN_HAVE_MPI
#include <dlfcn.h>

#include "vdyn/core/sweep_mpi.h"
#endif

namespace vdyn::cli {

namespace {

#ifdef VDYN_HAVE_MPI
/// The MPI runner's entry (vdyn_sweep_mpi.h: vdyn_run_sweep_mpi_job), from
/// the library opened on the first --mpi run only: vdyn is not linked to
/// it, so a process without --mpi does not load Open MPI's seven libraries
/// (about 2 ms of user CPU per start; docs/benchmarks.md). The library is the
/// build's own (its soname, VDYN_SWEEP_MPI_LIBRARY, found along vdyn's
/// run path: build/lib, or the installed lib folder); RTLD_GLOBAL, since Open
/// MPI's components, which it opens in turn, resolve symbols of libmpi.
using SweepMpiEntry = void (*)(SweepMpiJob*, const char*);
SweepMpiEntry loadSweepMpiRunner() {
  void* lib = dlopen(VDYN_SWEEP_MPI_LIBRARY, RTLD_NOW | RTLD_GLOBAL);
  if (!lib)
    throw Error(std::string("--mpi: the MPI sweep runner ") + VDYN_SWEEP_MPI_LIBRARY + " could not be loaded: " +
                dlerror());
  dlerror();
  void* entry = dlsym(lib, "vdyn_run_sweep_mpi_job");
  if (!entry) {
    const char* why = dlerror();
    throw Error(std::string("--mpi: ") + VDYN_SWEEP_MPI_LIBRARY + " has no vdyn_run_sweep_mpi_job: " +
                (why ? why : "the symbol is null"));
  }
  return reinterpret_cast<SweepMpiEntry>(entry);
}
#endif

/// The last key of a (checked) key path with any indices after it: "steps[1]" of "a.steps[1]".
std::string lastSegment(const std::string& path) {
  const KeyPath k = KeyPath::parse(path, "sweep");
  std::size_t last = k.parts().size() - 1;
  while (last > 0 && k.parts()[last].bracketed) --last;
  return k.tail(last).format();
}

/// Renders the sweep file's plots from results.csv with gnuplot (script kept as <png>.gp).
void renderSweepPlots(const SweepDescription& d, const SweepResult& r, const std::string& dir) {
  if (d.plots.empty()) return;
  if (!gnuplotAvailable()) throw Error("gnuplot not found: the sweep's plots need it (apt-get install gnuplot-nox)");
  const std::string csv = dir + "/results.csv";
  // The text of a key's or collected column's value in a row ("" if none).
  auto fieldOf = [&](const SweepRow& row, const std::string& column) -> std::string {
    const auto k = std::find(d.keys.begin(), d.keys.end(), column);
    if (k != d.keys.end()) {
      const Json* x = d.variations[row.index].find(column);
      return x ? formatSweepField(*x) : "";
    }
    const auto c = std::size_t(std::find(d.collect.begin(), d.collect.end(), column) - d.collect.begin());
    return row.ok && c < row.values.size() ? formatSweepField(row.values[c]) : "";
  };
  // The distinct values of a key or collected column, in row order.
  auto distinct = [&](const std::string& column) {
    std::vector<std::string> v;
    if (column.empty()) return std::vector<std::string>{""};
    for (const SweepRow& row : r.rows) {
      const std::string text = fieldOf(row, column);
      if (!text.empty() && std::find(v.begin(), v.end(), text) == v.end()) v.push_back(text);
    }
    return v;
  };
  // True if a row that succeeded has an x and a y in `panel`'s `series`.
  auto hasPoint = [&](const SweepPlot& p, const std::string& panel, const std::string& series) {
    for (const SweepRow& row : r.rows)
      if (row.ok && (p.panels.empty() || fieldOf(row, p.panels) == panel) &&
          (p.series.empty() || fieldOf(row, p.series) == series) && !fieldOf(row, p.x).empty() &&
          !fieldOf(row, p.y).empty())
        return true;
    return false;
  };
  for (const SweepPlot& p : d.plots) {
    const auto panels = distinct(p.panels), series = distinct(p.series);
    PlotSpec fig;
    fig.name = p.png;
    fig.title = p.title;
    for (const std::string& panel : panels) {
      PlotSpec q;
      q.xlabel = p.x_label.empty() ? p.x : p.x_label;
      q.ylabel = p.y_label.empty() ? p.y : p.y_label;
      q.title = p.panels.empty() ? p.title
                                 : (p.panel_label.empty() ? lastSegment(p.panels) : p.panel_label) + " = " + panel;
      for (const std::string& s : series) {
        // Every panel draws the same series (the same colours and one legend),
        // less those without a point in any panel; a panel with no point at
        // all is drawn empty (gnuplot cannot draw it).
        if (!std::any_of(panels.begin(), panels.end(), [&](const std::string& q) { return hasPoint(p, q, s); }))
          continue;
        PlotSeries c{csv, p.x, p.y,
                     p.series.empty() ? lastSegment(p.y)
                                      : (p.series_label.empty() ? lastSegment(p.series) : p.series_label) + " = " + s};
        c.x_scale = p.x_scale, c.y_scale = p.y_scale;
        c.where = {{"status", "ok"}};
        if (!p.panels.empty()) c.where.emplace_back(p.panels, panel);
        if (!p.series.empty()) c.where.emplace_back(p.series, s);
        c.style = "with linespoints lw 2 pt 7 ps 0.6";
        q.series.push_back(c);
      }
      if (!std::any_of(series.begin(), series.end(), [&](const std::string& s) { return hasPoint(p, panel, s); })) {
        q.series.clear();
        q.title += ": no point (no row ok; results.csv's status and reason say why)";
      }
      fig.panels.push_back(q);
    }
    if (fig.panels.size() == 1 && p.panels.empty()) {  // one panel: the figure itself
      const std::string title = fig.title;
      fig = fig.panels.front();
      fig.title = title;
    }
    renderFigure(fig, dir + "/" + p.png, [](const std::string& path) { return path; });
  }
}

}  // namespace

int sweepCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("sweep", po::value<std::string>(), "sweep file (JSON; see docs/user_guide.md, \"Sweeps\")")(
      "threads", po::value<int>(),
      "worker threads (default: one per core; with --mpi: threads on rank 0 besides managing, default 1, "
      "0 = rank 0 only manages)")(
      "mpi", "run over MPI processes (start with mpirun -n N): rank 0 hands out variations one at a time")(
      "out", po::value<std::string>(), "output folder (default: the sweep file's \"output\", else ./results/sweeps/<name>)")(
      "fresh", "ignore and overwrite the journal of an earlier run (default: resume, skipping runs already done)")(
      "retry-failed", "when resuming, run the failed variations again")(
      "run-files", "also write each run's files (summary.json, tables) to <out>/runs/<variation>/")(
      "no-plots", "skip the sweep file's plots")("quiet", "no progress lines");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("sweep"), args, opts, {"sweep"}, vm)) return 0;
  if (!vm.count("sweep")) throw Error("bad command line: no sweep file given (vdyn sweep SWEEP)");
  const bool useMpi = vm.count("mpi") > 0;
#ifndef VDYN_HAVE_MPI
  if (useMpi) throw Error("--mpi: this vdyn was built without MPI (install libopenmpi-dev and rebuild)");
#endif

  // Everything a run needs is loaded and checked before any run (and before
  // threads start: plugin libraries change the registry).
  const SweepDescription sweep = SweepDescription::fromFile(resolveDataPath(vm["sweep"].as<std::string>()));
  PluginRegistry& registry = registryWithPlugins(vm);
  const std::string out = vm.count("out") ? vm["out"].as<std::string>()
                          : !sweep.output.empty() ? sweep.output
                                                  : "results/sweeps/" + sweep.name;
  const SweepRunFunction run = makeSceneSweepRun(sweep, registry, vm.count("run-files") ? out + "/runs" : "");

  SweepOptions so;
  so.out_dir = out;
  so.resume = vm.count("fresh") == 0;
  so.retry_failed = vm.count("retry-failed") > 0;
  const bool quiet = vm.count("quiet") > 0;
  SweepResult r;
  bool manager = true;
  if (useMpi) {
#ifdef VDYN_HAVE_MPI
    const SweepMpiEntry runMpi = loadSweepMpiRunner();
    SweepMpiJob job;
    job.sweep = &sweep;
    job.run = &run;
    job.options = so;
    job.options.threads = vm.count("threads") ? vm["threads"].as<int>() : 1;
    if (!quiet) job.options.progress = sweepProgressPrinter("vdyn sweep");
    if (!vm.count("no-plots")) job.on_manager = [&](const SweepResult& res) { renderSweepPlots(sweep, res, out); };
    runMpi(&job, "vdyn sweep");
    r = std::move(job.result);
    manager = job.manager;
#endif
  } else {
    so.threads = vm.count("threads") ? vm["threads"].as<int>() : int(std::max(1u, std::thread::hardware_concurrency()));
    if (!quiet) so.progress = sweepProgressPrinter("vdyn sweep");
    installInterruptHandlers();  // SIGINT/SIGTERM: stop between variations, write the finished rows
    r = runSweep(sweep, run, so);
    if (!vm.count("no-plots")) renderSweepPlots(sweep, r, out);
  }
  if (!manager) return 0;
  std::string named;  // e.g. ", 40 beyond_fold": rows that are a named outcome, not a failure
  for (const auto& [status, count] : r.outcomes) named += ", " + std::to_string(count) + " " + status;
  std::printf("vdyn sweep: %s: %zu variations, %zu run now (%zu from the journal), %zu failed%s; %.2f s wall, %.2f s "
              "CPU, %d %s\n",
              sweep.name.c_str(), sweep.variations.size(), r.ran, r.resumed, r.failed, named.c_str(), r.wall_s, r.cpu_s,
              r.workers,
              r.runner == "mpi" ? "MPI workers" : "threads");
  std::printf("  %s/results.csv, results.json, sweep_stats.json%s\n", out.c_str(),
              sweep.plots.empty() || vm.count("no-plots") ? "" : ", plots");
  int shown = 0;
  for (const SweepRow& row : r.rows)
    if (sweepStatus(row) == "failed" && shown++ < 5)
      std::printf("  variation %zu failed: %s\n", row.index, row.reason.c_str());
  return 0;
}

}  // namespace vdyn::cli
