#pragma once
// Conventions every study follows (docs/conventions.md "Studies"): options with units in
// their names, --out DIR (default results/<study>/), summary.json, CSV with a
// header row, PNG plots, a printed table, exit 0 on success and non-zero with a
// one-line message on a user error or numerical failure.
#include <functional>
#include <string>
#include <vector>

#include <boost/program_options.hpp>
#include <SimTKcommon.h>

#include "vdyn/core/file_io.h"
#include "vdyn/core/integrators.h"
#include "vdyn/core/params.h"

namespace vdyn::study {

namespace po = boost::program_options;

/// Runs `body`; returns 0, or prints "<study>: error: <message>" and returns 1.
/// If the output folder exists and no summary.json was written, it writes
/// {"completed": false, "error": message} there.
int run(const std::string& study, const std::function<void()>& body);

/// Parses the command line. Adds --help and --out; on --help prints the options
/// and exits 0. Throws Error on unknown or malformed options.
po::variables_map parse(const std::string& study, const std::string& summary, int argc, char** argv,
                        po::options_description& options);

/// A number the user gave, with the name they gave it by: "--speed-m-s" for an
/// option, "ch3_transient.json: speed_m_s" for a data-file key. Checks and
/// messages use `name`, so an error names what the user wrote.
struct Given {
  double value = 0;
  std::string name;
};
/// The option's value times `scale` if the option is given (deg -> rad), else
/// the data file's required key.
Given optionOr(const po::variables_map& vm, const std::string& option, const ParamReader& data,
               const std::string& key, double scale = 1.0);
/// The option's value (scaled) if given, else `fallback` under `fallbackName`.
Given optionOr(const po::variables_map& vm, const std::string& option, double fallback,
               const std::string& fallbackName, double scale = 1.0);

/// Physical ranges (bounds in the message): a forward speed in (0, 100] m/s
/// (`allowZero`: [0, 100]); a road-wheel steering angle in [-45, 45] deg.
double checkSpeed(const Given& g, bool allowZero = false);
/// A rolling speed in [min_m_s, 100] m/s: `why` says what needs it.
double checkSpeedAtLeast(const Given& g, double min_m_s, const std::string& why);
double checkSteerAngle(const Given& g, bool optionInDeg);
/// A run's end time (finite, > 0, at most 1e5 s) and report interval (> 0, at
/// most the run, and at most 1e6 samples), named as given.
void checkRunTimes(const Given& tEnd, const Given& reportInterval);

/// Whether a recorded history ended steady: over the last `window_s` of the run
/// (which must start after `settled_s`, when every command has settled) every
/// sample lies within rel_tol |y_end| + abs_tol of the final value.
struct SteadyVerdict {
  bool steady = false;
  std::string reason;  ///< why not (empty when steady)
  double spread = 0;   ///< largest |y - y_end| over the window
  double tolerance = 0;
  Json toJson() const;
};
SteadyVerdict checkSteady(const std::vector<double>& t, const std::vector<double>& y, const std::string& name,
                          double settled_s, double window_s, double rel_tol, double abs_tol);

/// Adds --integrator NAME and --accuracy X (every study that integrates takes them).
void addIntegratorOptions(po::options_description& options);
/// Applies --integrator and --accuracy, where given, over `settings` (read from a data file).
void applyIntegratorOptions(const po::variables_map& vm, IntegratorSettings& settings);

/// The output folder (created, checked writable; an old summary.json in it is
/// removed): --out, or <repo>/results/<study>.
std::string outputDir(const po::variables_map& vm, const std::string& study);

/// Writes JSON (pretty) to a file, atomically: the text goes to "<path>.tmp",
/// every write is checked (a full disk is a named Error), and the file is
/// renamed to `path` only when complete, so `path` is never half-written.
/// A summary.json object without "completed" gets "completed": true.
void writeJson(const std::string& path, const Json& j);

/// One line series of a plot, read from a CSV file by column names.
struct Series {
  std::string csv;
  std::string x, y;   ///< column names
  std::string label;
  /// Optional "column=value[;column=value...]": only rows where every column
  /// equals its value (compared as text).
  std::string filter = "";
  /// Optional gnuplot style replacing the plot's default ("with points pt 6 lc 2"):
  /// e.g. stable points filled, unstable ones open.
  std::string style = "";
};

struct PlotSpec {
  std::string png;    ///< output file
  std::string title, xlabel, ylabel;
  std::vector<Series> series;
  bool equal_axes = false;  ///< same scale on x and y (trajectories)
  bool logx = false, logy = false;
  bool points = false;      ///< lines with point markers
};

/// Renders the plots with gnuplot (pngcairo). Throws Error if gnuplot is missing
/// or fails. The scripts are kept next to the PNGs (<png>.gp).
void plot(const std::vector<PlotSpec>& plots);

/// True when stderr is a terminal (progress output is shown only then).
bool interactive();

/// A step callback for vdyn::simulate that shows "<label>: t = x / t_end s" on
/// a terminal (at most every 0.2 s of wall time, cleared at the end) or, when
/// stderr is not a terminal, prints such a line every 10 s of wall time (a
/// long run in a log is never silent). Its cost: one clock read per step.
std::function<void(const SimTK::State&)> progress(const std::string& label, double t_end_s);
/// Clears the progress line (call after the run).
void endProgress();

}  // namespace vdyn::study
