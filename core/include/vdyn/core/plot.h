#pragma once
// PNG plots of an analysis's tables with gnuplot (pngcairo), as the studies
// draw theirs: the CSV files are the data, the gnuplot script is kept next to
// each PNG (<name>.png.gp) so a user can restyle it.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "vdyn/core/analysis.h"

namespace vdyn {

/// True if gnuplot is on the PATH.
bool gnuplotAvailable();

/// `s` as a gnuplot string literal: in double quotes, `"` and `\` escaped.
std::string gnuplotQuote(const std::string& s);

/// Runs gnuplot on the script file `script` (which writes `png`); gnuplot's
/// messages go to <png>.log, removed when it succeeds. Throws Error naming the
/// script and gnuplot's last message when it fails.
void runGnuplot(const std::string& script, const std::string& png);

/// The unit a column name ends in, by the project's naming convention
/// ("yaw_rate_rad_s" -> "rad/s", "Fz_N" -> "N", "t_s" -> "s"), or "".
std::string unitOfColumn(const std::string& column);

/// The one gnuplot writer (analyses, studies and sweeps draw through it).
/// Renders `figure` (one panel, or its `panels` in a grid) to `png`, keeping
/// the script as <png>.gp; `csvPath(table)` names each series' CSV file.
/// Legends sit below their panel (never over the data), once for a run of
/// panels with the same series labels; tick labels use at
/// most 4 significant digits; markers are dashed vertical lines with their
/// label. Throws Error if gnuplot is missing or fails.
void renderFigure(const PlotSpec& figure, const std::string& png,
                  const std::function<std::string(const std::string& table)>& csvPath);

/// Renders `plots` (their tables already written as <out_dir>/<table>.csv)
/// and, for every table no plot names, default pages: each column with a
/// finite point against the first, one panel each, in pages of at most
/// `panels_per_page` panels (<table>.png, <table>_2.png, ...), the columns
/// grouped by the name before their first '.' (a plugin or body) so a group
/// stays on one page where it fits; every column is drawn, and an angle
/// column (ending in _rad) that jumps by more than pi between rows is drawn
/// unwrapped (said in its panel title). Series without a finite point are
/// left out (a plot with none is not drawn). Returns the PNG paths written.
/// Throws Error if gnuplot is missing or fails, or a plot names a table or
/// column that is not there.
std::vector<std::string> renderPlots(const std::string& out_dir,
                                     const std::vector<std::pair<std::string, Table>>& tables,
                                     const std::vector<PlotSpec>& plots, int panels_per_page = 9);

}  // namespace vdyn
