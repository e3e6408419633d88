#pragma once
// Sweeps: many runs of one scene, each with a few settings changed (a
// variation), and a table of chosen quantities from each run's summary.
//
//  - SweepDescription: what to run. Read from a sweep file (JSON, strict keys;
//    format in docs of fromFile below and in docs/user_guide.md, "Sweeps") or built in C++.
//    Variations come from a full-factorial grid, an explicit list, a Latin
//    hypercube or Monte Carlo samples with a seed (SweepRandom: xoshiro256**,
//    identical on every platform; never std::*_distribution, whose output is
//    implementation-defined).
//  - runSweep(): the in-process runner. Worker threads take variations one at a
//    time (dynamic load balancing), each run builds its own Simbody system (the
//    run function must be safe to call from several threads on different
//    variations). A run that throws is a failed row carrying the message; one
//    that throws a NamedOutcome (vdyn/core/named_outcome.h) is a row with that
//    outcome's status (e.g. beyond_fold), counted apart from the failed ones.
//  - With an output folder: every finished run is appended to runs.jsonl at
//    once (one line, flushed), so a killed sweep resumes where it stopped
//    (runs already in the journal are skipped); results.csv and results.json,
//    ordered by variation, are written (atomically) at the end. They are
//    byte-identical whatever the number of threads or MPI ranks: numbers are
//    printed with shortest round-trip precision, timings live apart in
//    sweep_stats.json.
// The MPI runner (vdyn/core/sweep_mpi.h, target vdyn_sweep_mpi) shares all of
// this and differs only in who runs a variation.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/file_io.h"
#include "vdyn/core/params.h"

namespace vdyn {

/// The most variations a sweep file may describe (checked before any is
/// built: a grid's size is the product of its axes' counts).
constexpr std::size_t kMaxSweepVariations = 1000000;

/// One changed setting: a KeyPath into the scene ("a.b[2].c", vdyn/core/key_path.h) and its value.
struct SweepSetting {
  std::string key;
  Json value;
};

/// One run of a sweep.
struct Variation {
  std::size_t index = 0;              ///< 0-based row number (output order)
  std::vector<SweepSetting> settings; ///< in the sweep's key order
  /// Canonical text of the settings ("key=value;..." with values as compact
  /// JSON): identifies the variation in the journal on resume.
  std::string id() const;
  /// The value set for `key`, or nullptr.
  const Json* find(const std::string& key) const;
};

/// A grid axis: one or more keys that change together (values[i][k] is key k's
/// value at step i of the axis).
struct GridAxis {
  std::vector<std::string> keys;
  std::vector<std::vector<Json>> values;
};
/// Full factorial over the axes; the first axis varies slowest.
std::vector<std::vector<SweepSetting>> makeGridVariations(const std::vector<GridAxis>& axes);

/// A sampled key: uniform on [min, max].
struct SampleRange {
  std::string key;
  double min = 0, max = 1;
};
/// Latin hypercube: each key's range cut into `samples` strata, each stratum
/// used once, a uniform point within it; strata paired by random permutations.
std::vector<std::vector<SweepSetting>> makeLatinHypercubeVariations(const std::vector<SampleRange>& ranges,
                                                                    int samples, std::uint64_t seed);
/// Monte Carlo: independent uniform samples.
std::vector<std::vector<SweepSetting>> makeMonteCarloVariations(const std::vector<SampleRange>& ranges,
                                                                int samples, std::uint64_t seed);

/// xoshiro256** seeded by splitmix64 (Blackman and Vigna); integer arithmetic
/// and one exact scaling, so a seed gives the same numbers on every platform.
class SweepRandom {
 public:
  explicit SweepRandom(std::uint64_t seed);
  std::uint64_t next();
  /// Uniform on [0, 1) with 53 random bits.
  double uniform();
  /// Uniform integer in [0, n) without modulo bias (n > 0).
  std::uint64_t below(std::uint64_t n);

 private:
  std::uint64_t s_[4];
};

/// A plot of the results (rendered by `vdyn sweep` with gnuplot from
/// results.csv): y against x, one line per value of `series`, one panel per
/// value of `panels`. Columns are varied keys or collected paths.
struct SweepPlot {
  std::string png;              ///< file name in the output folder
  std::string title;
  std::string x, y;             ///< columns
  double x_scale = 1, y_scale = 1;  ///< plotted: column value times the scale
  std::string x_label, y_label; ///< axis labels (default: the column names)
  std::string series;           ///< column: one line per value ("" = one line)
  std::string panels;           ///< column: one panel per value ("" = one panel)
  std::string series_label, panel_label;  ///< legend / panel title prefixes (default: the column's last segment)
};

struct SweepDescription {
  std::string file;      ///< the sweep file ("" when built in C++); names it in messages
  std::string name;      ///< sweep name (default: the file's stem)
  std::string scene;     ///< the scene file: in the sweep file's folder if there, else as given (data path)
  std::vector<SweepSetting> common;   ///< "set": applied to every run before its variation
  std::vector<std::string> keys;      ///< every varied key path, in column order
  std::vector<Variation> variations;  ///< in output order (index = position)
  std::vector<std::string> collect;   ///< summary paths collected into columns
  std::string output;    ///< output folder from the file ("" if not given)
  std::vector<SweepPlot> plots;       ///< "plots"

  /// Reads a sweep file. Top-level keys (all but scene and variations optional):
  ///   "scene": "file.json"               scene file (relative to the sweep file)
  ///   "name": "text"                     default: the file's stem
  ///   "set": {"key.path": value, ...}    overrides applied to every run
  ///   "variations": [block, ...]         concatenated in order; a block is one of
  ///     {"grid": [axis, ...]}            axis: {"key": "k", "values": [...]} or
  ///                                      {"key": "k", "from": a, "to": b, "count": n}
  ///                                      (n evenly spaced, ends included) or
  ///                                      {"keys": ["k1", "k2"], "values": [[v1, v2], ...]}
  ///     {"list": [{"key.path": value, ...}, ...]}
  ///     {"latin_hypercube" | "monte_carlo": {"samples": n, "seed": s,
  ///                                          "ranges": {"key": [min, max], ...}}}
  ///   "collect": ["summary.path", ...]   quantities from each run's summary
  ///   "output": "folder"                 relative to the sweep file
  ///   "plots": [{"png": "f.png", "x": column, "y": column, "series": column,
  ///              "panels": column, "title", "x_label", "y_label", "x_scale",
  ///              "y_scale", "series_label", "panel_label"}]
  ///                                      columns: varied keys or collected paths
  /// Unknown keys, wrong types, empty sets and duplicate keys are vdyn::Error
  /// naming the file, the key path and the value.
  static SweepDescription fromFile(const std::string& path);
  /// The same from JSON; `where` names it in messages, `baseDir` resolves paths.
  static SweepDescription fromJson(const Json& j, const std::string& where, const std::string& baseDir);

  /// Appends variations (their indices follow the existing ones) and records
  /// new keys in `keys`.
  void addVariations(const std::vector<std::vector<SweepSetting>>& sets);
  /// Hash of everything that defines the rows (keys, variation ids, collect):
  /// MPI ranks check they read the same sweep.
  std::uint64_t fingerprint() const;
};

/// The result of one variation.
struct SweepRow {
  std::size_t index = 0;
  bool ok = false;             ///< the run gave a summary (status "ok")
  std::string outcome;         ///< not ok: the NamedOutcome's status, "" for a failure
  std::string reason;          ///< why it failed or has no result ("" when ok)
  std::vector<Json> values;    ///< one per collected path (null when failed)
  Json summary;                ///< the run's whole summary (null when failed)
  double wall_s = 0, cpu_s = 0;  ///< the run's wall and CPU (its thread's) time
  bool resumed = false;        ///< taken from the journal, not run now
};

/// The row's status: "ok", its named outcome (e.g. "beyond_fold") or "failed".
std::string sweepStatus(const SweepRow& row);

/// What a run function gets and returns: a variation in, its summary out.
/// Throwing (any std::exception) makes the row a failure with the message; a
/// NamedOutcome makes it a row of that status.
/// Called concurrently from several threads for different variations.
using SweepRunFunction = std::function<Json(const SweepDescription&, const Variation&)>;

class PluginRegistry;
/// The run function of a sweep of scene files, as `vdyn sweep` and the Python
/// module's vdyn.sweep run it: the scene file d.scene with the sweep's "set"
/// (d.common) applied, its plugin libraries loaded into `registry` (here,
/// before any thread starts), and variation 0 checked the way build() checks a
/// scene (a misspelt key path would fail every run: Error naming the sweep
/// file, the variation and the first error). Each run is runScene() of that
/// scene with the variation's settings as overrides, without plots; with
/// `runFilesDir`, its files go to <runFilesDir>/<variation index>/.
SweepRunFunction makeSceneSweepRun(const SweepDescription& d, PluginRegistry& registry,
                                   const std::string& runFilesDir = "");

/// Runs one variation: calls `run`, times it, collects the values. Never throws
/// for a failing run: the row carries the reason.
SweepRow runVariation(const SweepDescription& d, const Variation& v, const SweepRunFunction& run);
/// Fills row.values from row.summary (a missing path fails the row, naming it).
void collectValues(const SweepDescription& d, SweepRow& row);

struct SweepProgress {
  std::size_t total = 0;    ///< variations in the sweep
  std::size_t skipped = 0;  ///< taken from the journal
  std::size_t done = 0;     ///< finished in this session (ok + failed + named outcomes)
  std::size_t failed = 0;   ///< of done
  std::map<std::string, std::size_t> outcomes;  ///< of done: rows per named outcome status
  double elapsed_s = 0;
  double eta_s = -1;        ///< estimated time left (-1 before the first run)
};
/// Prints "<label>: 37/216 runs (2 failed, 5 beyond_fold, 10 from the journal), 12 s, about 40 s left"
/// on stderr: a rewritten line on a terminal, else a line at most every 5 s.
std::function<void(const SweepProgress&)> sweepProgressPrinter(const std::string& label);

struct SweepOptions {
  int threads = 1;           ///< worker threads (>= 1)
  std::string out_dir;       ///< "" = in memory only: no journal, no files
  bool resume = true;        ///< skip runs already in the journal
  bool retry_failed = false; ///< ... except failed ones (not named outcomes), which run again
  std::function<void(const SweepProgress&)> progress;  ///< after each finished run
};

struct SweepResult {
  std::vector<SweepRow> rows;  ///< every variation, in order
  std::size_t ran = 0, failed = 0, resumed = 0;  ///< failed: status "failed" only
  std::map<std::string, std::size_t> outcomes;     ///< rows per named outcome status (every row, resumed too)
  double wall_s = 0;           ///< wall time of this session
  double cpu_s = 0;            ///< process CPU time of this session (all threads)
  int workers = 0;             ///< threads or ranks that ran variations
  std::string runner;          ///< "threads" or "mpi"
  /// Stopped by SIGINT/SIGTERM (thread runner): `rows` holds only the finished
  /// variations, and results.json and sweep_stats.json say "partial": true.
  bool partial = false;
  std::string interrupted_by;  ///< "SIGINT", "SIGTERM" when partial
};

/// Runs the sweep on `options.threads` threads (dynamic: one variation at a
/// time). With an output folder: resumes from and appends to runs.jsonl, then
/// writes results.csv, results.json and sweep_stats.json.
SweepResult runSweep(const SweepDescription& d, const SweepRunFunction& run, const SweepOptions& options);

/// Independent jobs of one program (a study's or an analysis's runs whose
/// results go to slots indexed by job) through the sweep runner's threads:
/// job(i) for every i in [0, n), taken one at a time by up to `threads`
/// (>= 1) threads (1: in the calling thread, in order). Each job must build
/// what it mutates (its own scene, system and state) and write only its own
/// slot, so the results do not depend on the number of threads. After all
/// jobs end, the failure of the lowest index, if any, is rethrown as Error
/// with its message. Returns the wall and CPU time (the process's, all threads).
struct JobsTiming {
  double wall_s = 0, cpu_s = 0;
  int workers = 0;
};
JobsTiming runJobs(std::size_t n, int threads, const std::function<void(std::size_t)>& job);
/// The machine's cores (std::thread::hardware_concurrency, at least 1): the
/// default thread count of the studies and analyses that run jobs.
int hardwareThreads();

// --- pieces shared with the MPI runner ------------------------------------------
/// Journal line of a row (compact JSON, no line break).
std::string sweepJournalLine(const SweepDescription& d, const SweepRow& row);
/// Parses a journal line back (values re-collected from the stored summary).
SweepRow parseSweepJournalLine(const SweepDescription& d, const std::string& line, const std::string& where);
/// Rows in `dir`/runs.jsonl that match `d`'s variations (last line per index
/// wins). A line whose variation differs from `d` is an Error naming it.
std::vector<SweepRow> readSweepJournal(const SweepDescription& d, const std::string& dir);
/// Opens `dir`/runs.jsonl for appending (resume) or anew; a last line without
/// its line break gets one first.
std::unique_ptr<AppendFile> openSweepJournal(const std::string& dir, bool append);
/// Prepares a run of `d` for either runner: sizes `res.rows`, creates `o.out_dir`,
/// takes the rows already in its journal (o.resume; failed ones again if
/// o.retry_failed) into `res.rows` and `res.resumed`, and opens the journal into
/// `journal` (null when o.out_dir is ""). Returns the variation indices still to run,
/// ascending.
std::vector<std::size_t> prepareSweepRun(const SweepDescription& d, const SweepOptions& o, SweepResult& res,
                                         std::unique_ptr<AppendFile>& journal);
/// Ends a run of either runner: counts the failed rows into `res.failed` and the
/// named outcomes into `res.outcomes`, sets
/// `res.wall_s` and `res.cpu_s` (since `start` and processCpuSeconds() = `cpu0`)
/// and writes the outputs into o.out_dir (writeSweepOutputs; none when "").
void finishSweepRun(const SweepDescription& d, const SweepOptions& o, SweepResult& res,
                    std::chrono::steady_clock::time_point start, double cpu0);
/// results.csv text: variation,status,<keys>,<collect>,reason (status: sweepStatus).
std::string formatSweepCsv(const SweepDescription& d, const std::vector<SweepRow>& rows);
/// results.json text.
std::string formatSweepJson(const SweepDescription& d, const std::vector<SweepRow>& rows);
/// A value as one CSV field (numbers in shortest round-trip form).
std::string formatSweepField(const Json& v);
/// Writes results.csv, results.json (atomically) and sweep_stats.json into `dir`.
void writeSweepOutputs(const SweepDescription& d, const SweepResult& r, const std::string& dir);
/// Process CPU time, s (all threads).
double processCpuSeconds();

}  // namespace vdyn
