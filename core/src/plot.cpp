#include "vdyn/core/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>

#include "vdyn/core/file_io.h"

namespace vdyn {

namespace {
const Table& findTable(const std::vector<std::pair<std::string, Table>>& tables, const std::string& name,
                       const std::string& plot) {
  for (const auto& [n, t] : tables)
    if (n == name) return t;
  throw Error("plot '" + plot + "': no table '" + name + "'");
}

void requireColumn(const Table& t, const std::string& table, const std::string& col, const std::string& plot) {
  if (std::find(t.columns.begin(), t.columns.end(), col) == t.columns.end())
    throw Error("plot '" + plot + "': table '" + table + "' has no column '" + col + "'");
}

/// True if column `c` has a finite value in a row where column `x` has one
/// (gnuplot fails on a plot whose points are all undefined).
bool hasPoints(const Table& t, std::size_t x, std::size_t c) {
  for (const auto& r : t.rows)
    if (x < r.size() && c < r.size() && std::isfinite(r[x]) && std::isfinite(r[c])) return true;
  return false;
}

std::size_t columnIndex(const Table& t, const std::string& c) {
  return std::size_t(std::find(t.columns.begin(), t.columns.end(), c) - t.columns.begin());
}

/// Writes <png>.gp (the terminal, the output and `script`) and runs it.
void renderPng(const std::string& png, const std::string& script) {
  const std::string gp = png + ".gp";
  writeFileAtomic(gp, "set terminal pngcairo size 1000,650 font 'sans,10'\nset output " + gnuplotQuote(png) +
                          "\nset datafile separator ','\nset grid\nset key noenhanced\n" + script);
  runGnuplot(gp, png);
}
}  // namespace

bool gnuplotAvailable() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

std::string gnuplotQuote(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

void runGnuplot(const std::string& script, const std::string& png) {
  const std::string cmd = "gnuplot " + gnuplotQuote(script) + " 2> " + gnuplotQuote(png + ".log");
  if (std::system(cmd.c_str()) != 0) {
    std::ifstream log(png + ".log");
    std::string line, last;
    while (std::getline(log, line))
      if (!line.empty()) last = line;
    throw Error("gnuplot failed on '" + script + "': " + last);
  }
  std::remove((png + ".log").c_str());
}

std::vector<std::string> renderPlots(const std::string& dir, const std::vector<std::pair<std::string, Table>>& tables,
                                     const std::vector<PlotSpec>& plots, int maxPanels) {
  std::vector<std::string> written;
  if (plots.empty() && tables.empty()) return written;
  if (!gnuplotAvailable())
    throw Error("gnuplot not found: the PNG plots need it (apt-get install gnuplot-nox), or run without plots");
  std::set<std::string> named;
  for (const PlotSpec& p : plots) {
    if (p.series.empty()) throw Error("plot '" + p.name + "': no series");
    std::string s = "set title " + gnuplotQuote(p.title) + " noenhanced\nset xlabel " + gnuplotQuote(p.xlabel) +
                    " noenhanced\nset ylabel " + gnuplotQuote(p.ylabel) + " noenhanced\n";
    if (p.equal_axes) s += "set size ratio -1\n";
    if (p.logx) s += "set logscale x\n";
    s += "plot ";
    int drawn = 0;
    for (std::size_t i = 0; i < p.series.size(); ++i) {
      const PlotSeries& q = p.series[i];
      const Table& t = findTable(tables, q.table, p.name);
      requireColumn(t, q.table, q.x, p.name);
      requireColumn(t, q.table, q.y, p.name);
      named.insert(q.table);
      if (!hasPoints(t, columnIndex(t, q.x), columnIndex(t, q.y))) continue;  // nothing to draw
      s += std::string(drawn++ ? ", \\\n     " : "") + gnuplotQuote(dir + "/" + q.table + ".csv") + " using (column(" +
           gnuplotQuote(q.x) + ")):(column(" + gnuplotQuote(q.y) + "))" +
           (p.points ? " with linespoints lw 2 pt 7" : " with lines lw 2") + " title " +
           gnuplotQuote(q.label.empty() ? q.y : q.label);
    }
    if (drawn == 0) continue;
    const std::string png = dir + "/" + p.name + ".png";
    renderPng(png, s + "\n");
    written.push_back(png);
  }
  for (const auto& [name, t] : tables) {
    if (named.count(name) || t.columns.size() < 2 || t.rows.empty()) continue;
    std::vector<std::size_t> cols;  // the columns with points to draw
    for (std::size_t c = 1; c < t.columns.size(); ++c)
      if (hasPoints(t, 0, c)) cols.push_back(c);
    if (cols.empty()) continue;
    const int n = std::min<int>(int(cols.size()), maxPanels);
    const int nc = n <= 3 ? 1 : (n <= 8 ? 2 : 3), rows = (n + nc - 1) / nc;
    std::string s = "set multiplot layout " + std::to_string(rows) + "," + std::to_string(nc) + " title " +
                    gnuplotQuote(name + (int(cols.size()) > n ? " (first " + std::to_string(n) + " columns)" : "")) +
                    " noenhanced\nset key off\n";
    for (int k = 0; k < n; ++k) {
      const std::size_t i = cols[k];
      s += "set title " + gnuplotQuote(t.columns[i]) + " noenhanced\nset xlabel " + gnuplotQuote(t.columns[0]) +
           " noenhanced\nplot " + gnuplotQuote(dir + "/" + name + ".csv") + " using (column(" +
           gnuplotQuote(t.columns[0]) + ")):(column(" + gnuplotQuote(t.columns[i]) + "))" +
           (t.rows.size() < 40 ? " with linespoints pt 7" : " with lines") + " lw 2\n";
    }
    s += "unset multiplot\n";
    const std::string png = dir + "/" + name + ".png";
    renderPng(png, s);
    written.push_back(png);
  }
  return written;
}

}  // namespace vdyn
