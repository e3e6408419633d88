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

#include "vdyn/core/integrators.h"
#include "vdyn/core/params.h"

namespace vdyn::study {

namespace po = boost::program_options;

/// Runs `body`; returns 0, or prints "<study>: error: <message>" and returns 1.
int run(const std::string& study, const std::function<void()>& body);

/// Parses the command line. Adds --help and --out; on --help prints the options
/// and exits 0. Throws Error on unknown or malformed options.
po::variables_map parse(const std::string& study, const std::string& summary, int argc, char** argv,
                        po::options_description& options);

/// Adds --integrator NAME and --accuracy X (every study that integrates takes them).
void addIntegratorOptions(po::options_description& options);
/// Applies --integrator and --accuracy, where given, over `settings` (read from a data file).
void applyIntegratorOptions(const po::variables_map& vm, IntegratorSettings& settings);

/// The output folder (created): --out, or <repo>/results/<study>.
std::string outputDir(const po::variables_map& vm, const std::string& study);

/// Writes JSON (pretty) to a file; throws Error if it cannot.
void writeJson(const std::string& path, const Json& j);

/// One line series of a plot, read from a CSV file by column names.
struct Series {
  std::string csv;
  std::string x, y;   ///< column names
  std::string label;
  /// Optional "column=value[;column=value...]": only rows where every column
  /// equals its value (compared as text).
  std::string filter = "";
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
/// a terminal (at most every 0.2 s of wall time, cleared at the end), or an
/// empty callback, which costs nothing, when stderr is not a terminal.
std::function<void(const SimTK::State&)> progress(const std::string& label, double t_end_s);
/// Clears the progress line (call after the run).
void endProgress();

}  // namespace vdyn::study
