#pragma once
// The one idea of an analysis: a scene description and settings in; a summary
// (JSON), tables (CSV) and files out. Analyses are registered by name
// (transient, static_equilibrium, steady_state, continuation, stability,
// sensitivity, optimal_ratio, ...) and built from the scene file's "analysis"
// object, whose settings the factory reads (and so validates) at load time.
// Following the Drake convention, run() is public and non-virtual: it checks
// the context and calls the protected DoRun().
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <SimTKcommon.h>

#include "vdyn/core/params.h"

namespace vdyn {

class SceneDescription;
struct BuiltScene;
class AnimationRecorder;

/// A table: named columns of numbers (written as CSV with a header row).
struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  void writeCsv(const std::string& path) const;
};

/// One line of a plot: columns x and y of a table (an analysis's table by
/// name, or a CSV file by path where the caller resolves names so: see
/// renderFigure in plot.h).
struct PlotSeries {
  std::string table;          ///< a table of the same AnalysisResult (or a CSV path)
  std::string x, y;           ///< column names
  std::string label;          ///< legend ("" = the y column's name)
  double x_scale = 1, y_scale = 1;  ///< drawn: column x x_scale, column y x y_scale (unit conversion)
  /// Only rows where every (column, text) pair matches (compared as text).
  std::vector<std::pair<std::string, std::string>> where = {};
  std::string style = "";     ///< gnuplot style replacing the panel's ("with points pt 7")
  /// Remove the 2 pi x y_scale jumps of an angle wrapped to +-pi (yaw).
  bool unwrap = false;
};

/// A vertical line at x with a label (a limit, a fold, a resonance).
struct PlotMarker {
  double x = 0;
  std::string label;
};

/// A PNG an analysis asks for (rendered by runScene with gnuplot, plot.h):
/// one panel, or, when `panels` is not empty, a figure of those panels (the
/// figure's own series and axes unused) under `title`.
struct PlotSpec {
  std::string name;           ///< file <name>.png in the output folder
  std::string title, xlabel, ylabel;
  std::vector<PlotSeries> series;
  bool equal_axes = false;    ///< same scale on x and y (trajectories)
  bool logx = false;
  bool points = false;        ///< lines with point markers
  bool logy = false;
  /// Axis ranges in the drawn units (NaN: from the data).
  double x_min = NAN, x_max = NAN, y_min = NAN, y_max = NAN;
  std::vector<PlotMarker> markers = {};
  std::vector<PlotSpec> panels = {};
  int columns = 0;            ///< panels per row (0: chosen from their number)
};

/// What an analysis hands back.
struct AnalysisResult {
  Json summary = Json::object();                        ///< becomes summary.json
  std::vector<std::pair<std::string, Table>> tables;    ///< name -> <name>.csv
  /// PNGs; a table no plot names gets one of its own (every other column
  /// against the first, one panel each), so every analysis writes a PNG.
  std::vector<PlotSpec> plots;
  std::vector<std::string> files;                       ///< other files it wrote into the output folder
};

/// A step callback of simulate() showing progress, or an empty one.
using ProgressCallback = std::function<void(const SimTK::State&)>;
/// Makes a progress callback for a run labelled `label` ending at t_end_s.
using ProgressFactory = std::function<ProgressCallback(const std::string& label, double t_end_s)>;

/// What an analysis runs on.
struct AnalysisContext {
  /// The scene file (with overrides): analyses that need fresh scenes (sweeps,
  /// bisection over speed, design perturbations) build them from it with
  /// SceneDescription::withOverride(...).build().
  const SceneDescription& description;
  /// The scene built once from `description` (vehicle, plugins, outputs).
  BuiltScene& built;
  /// Output folder for the analysis's own files ("" = write none).
  std::string out_dir;
  /// Progress of long runs (empty = none).
  ProgressFactory progress;
  /// `vdyn run --animation`: the recorder of the run the analysis reports
  /// (its Recorder gets animation->observer(); an analysis that builds its own
  /// scene for that run calls animation->restart(scene) first). Null: none
  /// asked, and an analysis records nothing for it.
  AnimationRecorder* animation = nullptr;
};

class Analysis {
 public:
  virtual ~Analysis() = default;
  Analysis(const Analysis&) = delete;
  Analysis& operator=(const Analysis&) = delete;
  const std::string& type() const { return type_; }

  /// Runs the analysis. Throws Error naming the cause if it fails; a result
  /// is never returned for a run that failed or left its regime.
  AnalysisResult run(const AnalysisContext& context) const;

 protected:
  explicit Analysis(std::string type) : type_(std::move(type)) {}
  virtual AnalysisResult DoRun(const AnalysisContext& context) const = 0;

 private:
  std::string type_;
};

}  // namespace vdyn
