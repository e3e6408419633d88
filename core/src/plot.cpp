#include "vdyn/core/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>

#include "vdyn/core/file_io.h"

namespace vdyn {

namespace {
using CsvOf = std::function<std::string(const std::string&)>;

const Table& findTable(const std::vector<std::pair<std::string, Table>>& tables, const std::string& name,
                       const std::string& plot) {
  for (const auto& [n, t] : tables)
    if (n == name) return t;
  throw Error("plot '" + plot + "': no table '" + name + "'");
}

std::size_t columnIndex(const Table& t, const std::string& c) {
  return std::size_t(std::find(t.columns.begin(), t.columns.end(), c) - t.columns.begin());
}

void requireColumn(const Table& t, const std::string& table, const std::string& col, const std::string& plot) {
  if (columnIndex(t, col) == t.columns.size())
    throw Error("plot '" + plot + "': table '" + table + "' has no column '" + col + "'");
}

/// True if column `c` has a finite value in a row where column `x` has one
/// (gnuplot fails on a plot whose points are all undefined).
bool hasPoints(const Table& t, std::size_t x, std::size_t c) {
  for (const auto& r : t.rows)
    if (x < r.size() && c < r.size() && std::isfinite(r[x]) && std::isfinite(r[c])) return true;
  return false;
}

/// True if consecutive finite values of column c jump by more than pi (an
/// angle wrapped to +-pi).
bool jumpsByPi(const Table& t, std::size_t c) {
  double prev = NAN;
  for (const auto& r : t.rows) {
    if (c >= r.size() || !std::isfinite(r[c])) continue;
    if (std::isfinite(prev) && std::abs(r[c] - prev) > M_PI) return true;
    prev = r[c];
  }
  return false;
}

bool endsWith(const std::string& s, const std::string& e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

std::string num(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

std::string range(double lo, double hi) {
  return "[" + (std::isfinite(lo) ? num(lo) : std::string("*")) + ":" + (std::isfinite(hi) ? num(hi) : std::string("*")) +
         "]";
}

/// The gnuplot commands of one panel; `curve` numbers the unwrapping
/// variables across a figure.
std::string panelScript(const PlotSpec& p, const CsvOf& csvOf, int& curve, bool key = true) {
  std::string s = "unset arrow\nunset label\nunset logscale\nset size noratio\n";
  s += "set title " + gnuplotQuote(p.title) + " noenhanced\nset xlabel " + gnuplotQuote(p.xlabel) +
       " noenhanced\nset ylabel " + gnuplotQuote(p.ylabel) + " noenhanced\n";
  s += p.logx ? "set logscale x\nset format x '%g'\n" : "set format x '%.4g'\n";
  s += p.logy ? "set logscale y\nset format y '%g'\n" : "set format y '%.4g'\n";
  if (p.equal_axes) s += "set size ratio -1\n";
  s += "set xrange " + range(p.x_min, p.x_max) + "\nset yrange " + range(p.y_min, p.y_max) + "\n";
  int m = 0;
  for (const PlotMarker& k : p.markers) {
    ++m;
    s += "set arrow " + std::to_string(m) + " from " + num(k.x) + ", graph 0 to " + num(k.x) +
         ", graph 1 nohead dt 2 lw 1.5 lc rgb 'gray30'\n";
    s += "set label " + std::to_string(m) + " " + gnuplotQuote(k.label) + " at " + num(k.x) +
         ", graph 0.96 right offset -0.5,0 noenhanced tc rgb 'gray30'\n";
  }
  if (p.series.empty()) {
    // A panel with nothing to draw (a sweep's panel whose every row failed)
    // keeps its place in the grid, framed and labelled, instead of failing
    // gnuplot ("all points y value undefined").
    return s + "set key off\nset xrange [0:1]\nset yrange [0:1]\nset format x ''\nset format y ''\n"
               "set label 99 \"no point to draw\" at graph 0.5, graph 0.5 center noenhanced\nplot 2 notitle\n";
  }
  s += key && p.series.size() > 1 ? "set key below horizontal noenhanced\n" : "set key off\n";
  std::string plot;
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const PlotSeries& q = p.series[i];
    std::string y = "column(" + gnuplotQuote(q.y) + ")" + (q.y_scale != 1 ? "*" + num(q.y_scale) : "");
    std::string cond;
    for (const auto& [col, text] : q.where)
      cond += (cond.empty() ? "" : " && ") + std::string("strcol(") + gnuplotQuote(col) + ") eq " + gnuplotQuote(text);
    if (!cond.empty()) y = "((" + cond + ") ? " + y + " : NaN)";
    if (q.unwrap) {
      // Serial evaluation: offset o moves by whole periods so that each value
      // lies within half a period of the previous one drawn.
      const std::string k = std::to_string(++curve), o = "uw_o" + k, pv = "uw_p" + k, f = "uw_f" + k;
      const std::string period = num(2 * M_PI * q.y_scale);
      s += f + " = 1\n" + o + " = 0\n" + pv + " = 0\n";
      y = "(uw_v = " + y + ", " + o + " = " + f + " ? 0 : " + o + " - " + period + "*floor((uw_v + " + o + " - " + pv +
          ")/" + period + " + 0.5), " + f + " = 0, " + pv + " = uw_v + " + o + ", " + pv + ")";
    }
    const std::string style =
        !q.style.empty() ? q.style : (p.points ? "with linespoints lw 2 pt 7 ps 0.7" : "with lines lw 2");
    plot += std::string(plot.empty() ? "plot " : ", \\\n     ") + gnuplotQuote(csvOf(q.table)) + " using (column(" +
            gnuplotQuote(q.x) + ")" + (q.x_scale != 1 ? "*" + num(q.x_scale) : "") + "):(" + y + ") " + style +
            " title " + gnuplotQuote(q.label.empty() ? q.y : q.label);
  }
  return s + plot + "\n";
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

std::string unitOfColumn(const std::string& c) {
  // Longest suffix first: "_m_s2" before "_s2" and "_m_s" before "_s".
  static const std::vector<std::pair<std::string, std::string>> units = {
      {"_deg_per_m_s2", "deg/(m/s^2)"}, {"_rad_per_m_s2", "rad/(m/s^2)"}, {"_m_s2_per_rad", "(m/s^2)/rad"},
      {"_N_s_per_m", "N s/m"}, {"_N_per_m", "N/m"}, {"_1_per_s", "1/s"}, {"_per_s", "1/s"}, {"_rad_s2", "rad/s^2"},
      {"_rad_s", "rad/s"}, {"_m_s2", "m/s^2"}, {"_m_s", "m/s"}, {"_N_m", "N m"}, {"_kg_m2", "kg m^2"},
      {"_deg", "deg"}, {"_rad", "rad"}, {"_Hz", "Hz"}, {"_kg", "kg"}, {"_m", "m"}, {"_N", "N"}, {"_J", "J"},
      {"_W", "W"}, {"_s", "s"}};
  for (const auto& [suffix, unit] : units)
    if (endsWith(c, suffix)) return unit;
  return "";
}

void renderFigure(const PlotSpec& f, const std::string& png, const CsvOf& csvOf) {
  if (!gnuplotAvailable())
    throw Error("gnuplot not found: the PNG plots need it (apt-get install gnuplot-nox), or run without plots");
  std::string s = "set datafile separator ','\nset grid\nset tics font ',9'\n";
  int curve = 0;
  if (f.panels.empty()) {
    s = "set terminal pngcairo size 1000,650 font 'sans,10'\nset output " + gnuplotQuote(png) + "\n" + s +
        panelScript(f, csvOf, curve);
  } else {
    const int n = int(f.panels.size());
    const int nc = f.columns > 0 ? f.columns : (n <= 1 ? 1 : n <= 4 ? 2 : 3), nr = (n + nc - 1) / nc;
    s = "set terminal pngcairo size " + std::to_string(std::max(1000, 520 * nc)) + "," +
        std::to_string(380 * nr + 50) + " font 'sans,10'\nset output " + gnuplotQuote(png) + "\n" + s +
        "set multiplot layout " + std::to_string(nr) + "," + std::to_string(nc) + " title " + gnuplotQuote(f.title) +
        " noenhanced\n";
    // A legend once for a run of panels with the same series labels (a
    // sweep's panels), on the first of them.
    std::vector<std::string> previous;
    for (const PlotSpec& p : f.panels) {
      std::vector<std::string> labels;
      for (const PlotSeries& q : p.series) labels.push_back(q.label.empty() ? q.y : q.label);
      s += panelScript(p, csvOf, curve, labels != previous);
      previous = labels;
    }
    s += "unset multiplot\n";
  }
  writeFileAtomic(png + ".gp", s);
  runGnuplot(png + ".gp", png);
}

std::vector<std::string> renderPlots(const std::string& dir, const std::vector<std::pair<std::string, Table>>& tables,
                                     const std::vector<PlotSpec>& plots, int perPage) {
  std::vector<std::string> written;
  if (plots.empty() && tables.empty()) return written;
  if (!gnuplotAvailable())
    throw Error("gnuplot not found: the PNG plots need it (apt-get install gnuplot-nox), or run without plots");
  const CsvOf csvOf = [&](const std::string& table) { return dir + "/" + table + ".csv"; };
  std::set<std::string> named;
  // A panel keeps the series with points to draw; false if none is left.
  auto prune = [&](PlotSpec& p, const std::string& plot) {
    std::vector<PlotSeries> keep;
    for (const PlotSeries& q : p.series) {
      const Table& t = findTable(tables, q.table, plot);
      requireColumn(t, q.table, q.x, plot);
      requireColumn(t, q.table, q.y, plot);
      for (const auto& w : q.where) requireColumn(t, q.table, w.first, plot);
      named.insert(q.table);
      if (hasPoints(t, columnIndex(t, q.x), columnIndex(t, q.y))) keep.push_back(q);
    }
    p.series = keep;
    return !keep.empty();
  };
  for (PlotSpec p : plots) {
    if (p.panels.empty()) {
      if (p.series.empty()) throw Error("plot '" + p.name + "': no series");
      if (!prune(p, p.name)) continue;  // nothing to draw
    } else {
      std::vector<PlotSpec> keep;
      for (PlotSpec q : p.panels) {
        if (q.series.empty()) throw Error("plot '" + p.name + "': panel '" + q.title + "' has no series");
        if (prune(q, p.name)) keep.push_back(q);
      }
      if (keep.empty()) continue;
      p.panels = keep;
    }
    const std::string png = dir + "/" + p.name + ".png";
    renderFigure(p, png, csvOf);
    written.push_back(png);
  }
  for (const auto& [name, t] : tables) {
    if (named.count(name) || t.columns.size() < 2 || t.rows.empty()) continue;
    // Columns with points, grouped by the name before their first '.', in
    // the table's order of first appearance.
    std::vector<std::string> order;
    std::map<std::string, std::vector<std::size_t>> groups;
    for (std::size_t c = 1; c < t.columns.size(); ++c) {
      if (!hasPoints(t, 0, c)) continue;
      const std::string g = t.columns[c].substr(0, t.columns[c].find('.'));
      if (!groups.count(g)) order.push_back(g);
      groups[g].push_back(c);
    }
    std::vector<std::vector<std::size_t>> pages(1);
    std::vector<std::vector<std::string>> pageGroups(1);
    for (const std::string& g : order) {
      const auto& cols = groups[g];
      // A group starts a new page when it would not fit on the current one
      // but fits on an empty page.
      if (!pages.back().empty() && pages.back().size() + cols.size() > std::size_t(perPage) &&
          cols.size() <= std::size_t(perPage)) {
        pages.emplace_back();
        pageGroups.emplace_back();
      }
      for (std::size_t c : cols) {
        if (pages.back().size() == std::size_t(perPage)) {
          pages.emplace_back();
          pageGroups.emplace_back();
        }
        pages.back().push_back(c);
        if (pageGroups.back().empty() || pageGroups.back().back() != g) pageGroups.back().push_back(g);
      }
    }
    if (pages.front().empty()) continue;
    for (std::size_t k = 0; k < pages.size(); ++k) {
      PlotSpec fig;
      fig.name = k == 0 ? name : name + "_" + std::to_string(k + 1);
      fig.title = name;
      if (pages.size() > 1) {
        fig.title += " (page " + std::to_string(k + 1) + " of " + std::to_string(pages.size()) + ":";
        for (const auto& g : pageGroups[k]) fig.title += " " + g;
        fig.title += ")";
      }
      for (std::size_t c : pages[k]) {
        PlotSpec p;
        const std::string& col = t.columns[c];
        const bool unwrap = endsWith(col, "_rad") && jumpsByPi(t, c);
        p.title = col + (unwrap ? " (unwrapped)" : "");
        p.xlabel = t.columns[0];
        const std::string u = unitOfColumn(col);
        p.ylabel = u.empty() ? "" : "(" + u + ")";
        PlotSeries q{name, t.columns[0], col, ""};
        q.unwrap = unwrap;
        q.style = t.rows.size() < 40 ? "with linespoints lw 2 pt 7 ps 0.7" : "with lines lw 2";
        p.series = {q};
        fig.panels.push_back(p);
      }
      const std::string png = dir + "/" + fig.name + ".png";
      renderFigure(fig, png, csvOf);
      written.push_back(png);
    }
  }
  return written;
}

}  // namespace vdyn
