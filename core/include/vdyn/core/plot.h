#pragma once
// PNG plots of an analysis's tables with gnuplot (pngcairo), as the studies
// draw theirs: the CSV files are the data, the gnuplot script is kept next to
// each PNG (<name>.png.gp) so a user can restyle it.
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

/// Renders `plots` (their tables already written as <out_dir>/<table>.csv)
/// and, for every table no plot names, a default plot: each column against
/// the first, one panel per column (at most `max_panels`, the rest listed in
/// the title). Columns and series without a finite point are left out (a
/// plot with none is not drawn). Returns the PNG paths written. Throws Error if gnuplot is
/// missing or fails, or a plot names a table or column that is not there.
std::vector<std::string> renderPlots(const std::string& out_dir,
                                     const std::vector<std::pair<std::string, Table>>& tables,
                                     const std::vector<PlotSpec>& plots, int max_panels = 12);

}  // namespace vdyn
