#include "study.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <memory>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <unistd.h>

#include "vdyn/core/file_io.h"
#include "vdyn/core/interrupt.h"
#include "vdyn/core/plot.h"

namespace vdyn::study {

namespace {
std::string g_outputDir;        // outputDir() of this run, once created
bool g_summaryWritten = false;  // writeJson() wrote <out>/summary.json
}  // namespace

int run(const std::string& study, const std::function<void()>& body) {
  try {
    body();
    return 0;
  } catch (const Interrupted& e) {
    // Stopped at a safe point by SIGINT/SIGTERM: one line, exit 128 + signal.
    std::cerr << study << ": " << e.what() << std::endl;
    return 128 + e.signal();
  } catch (const std::exception& e) {
    const std::string msg = oneLineMessage(e);
    // The run failed before its summary: say so in summary.json, so that folder
    // never holds a summary that looks like a result (best effort: the error
    // itself may be that nothing can be written there).
    if (!g_outputDir.empty() && !g_summaryWritten) {
      try {
        writeJson(g_outputDir + "/summary.json", {{"completed", false}, {"error", msg}});
      } catch (const std::exception&) {
      }
    }
    std::cerr << study << ": error: " << msg << std::endl;
    return 1;
  }
}

po::variables_map parse(const std::string& study, const std::string& summary, int argc, char** argv,
                        po::options_description& options) {
  options.add_options()("help,h", "print this help and exit")(
      "out", po::value<std::string>(), "output folder (default: results/<study>/ in the repository)");
  po::variables_map vm;
  try {
    // No guessing of abbreviated options: "--speed 3" is not "--speed-m-s 3".
    const po::parsed_options parsed =
        po::command_line_parser(argc, argv)
            .options(options)
            .style(po::command_line_style::default_style & ~po::command_line_style::allow_guessing)
            .run();
    // A stray word (a value without its option, a misspelled "-out") is an
    // error, never silently ignored.
    for (const auto& o : parsed.options)
      if (o.position_key >= 0 || o.unregistered)
        throw Error("bad command line: unexpected argument '" +
                    (o.original_tokens.empty() ? o.string_key : o.original_tokens.front()) +
                    "' (options start with --; see --help)");
    po::store(parsed, vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw Error(std::string("bad command line: ") + e.what() + " (see --help)");
  }
  if (vm.count("help")) {
    std::cout << study << ": " << summary << "\n\n" << options << std::endl;
    std::exit(0);
  }
  return vm;
}

std::string outputDir(const po::variables_map& vm, const std::string& study) {
  const std::string dir = vm.count("out") ? vm["out"].as<std::string>() : std::string(VDYN_RESULTS_DIR) + "/" + study;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create output folder '" + dir + "': " + ec.message());
  // A summary of an earlier run must not pass for this one's.
  std::filesystem::remove(dir + "/summary.json", ec);
  if (ec) throw Error("cannot write to output folder '" + dir + "': " + ec.message());
  if (::access(dir.c_str(), W_OK) != 0)
    throw Error("cannot write to output folder '" + dir + "': " + std::strerror(errno));
  g_outputDir = dir;
  return dir;
}

void writeJson(const std::string& path, const Json& j) {
  const bool summary = path.size() >= 12 && path.compare(path.size() - 12, 12, "summary.json") == 0;
  std::string text;
  try {
    if (summary && j.is_object() && !j.contains("completed")) {
      Json withFlag = {{"completed", true}};
      withFlag.update(j);
      text = withFlag.dump(2) + "\n";
    } else {
      text = j.dump(2) + "\n";
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error("cannot write '" + path + "': " + e.what());
  }
  writeFileAtomic(path, text);
  if (summary) g_summaryWritten = true;
}


Given optionOr(const po::variables_map& vm, const std::string& option, const ParamReader& data, const std::string& key,
               double scale) {
  if (vm.count(option)) {
    data.has(key);  // the data file's value is overridden, not unknown
    return {requireFinite(vm[option].as<double>(), "--" + option) * scale, "--" + option};
  }
  return {data.number(key), data.at(key)};
}

Given optionOr(const po::variables_map& vm, const std::string& option, double fallback,
               const std::string& fallbackName, double scale) {
  if (vm.count(option)) return {requireFinite(vm[option].as<double>(), "--" + option) * scale, "--" + option};
  return {fallback, fallbackName};
}

double checkSpeed(const Given& g, bool allowZero) {
  requireFinite(g.value, g.name);
  if (!(allowZero ? g.value >= 0 : g.value > 0) || g.value > 100)
    throw Error(g.name + " must lie in " + (allowZero ? "[0" : "(0") + ", 100] m/s, got " + formatValue(g.value));
  return g.value;
}

double checkSpeedAtLeast(const Given& g, double lo, const std::string& why) {
  requireFinite(g.value, g.name);
  if (!(g.value >= lo) || g.value > 100)
    throw Error(g.name + " must lie in [" + formatValue(lo) + ", 100] m/s (" + why + "), got " + formatValue(g.value));
  return g.value;
}

double checkSteerAngle(const Given& g, bool optionInDeg) {
  const double deg = SimTK::Pi / 180;
  const bool option = g.name.rfind("--", 0) == 0;
  if (option && optionInDeg) {
    requireInRange(g.value / deg, -45, 45, g.name);
  } else {
    requireFinite(g.value, g.name);
    if (std::abs(g.value) > 45 * deg)
      throw Error(g.name + " must lie in [-0.785398, 0.785398] rad (+-45 deg), got " + formatValue(g.value));
  }
  return g.value;
}

Json SteadyVerdict::toJson() const {
  Json j = {{"steady", steady}, {"spread", spread}, {"tolerance", tolerance}};
  if (!steady) j["reason"] = reason;
  return j;
}

SteadyVerdict checkSteady(const std::vector<double>& t, const std::vector<double>& y, const std::string& name,
                          double settled_s, double window_s, double rel_tol, double abs_tol) {
  SteadyVerdict v;
  if (t.empty() || t.size() != y.size()) {
    v.reason = "no samples of " + name;
    return v;
  }
  const double tEnd = t.back(), yEnd = y.back();
  v.tolerance = rel_tol * std::abs(yEnd) + abs_tol;
  if (tEnd - window_s < settled_s) {
    v.reason = "the run ends at t = " + formatValue(tEnd) + " s, before a " + formatValue(window_s) +
               " s window after the commands settle at " + formatValue(settled_s) + " s";
    return v;
  }
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= tEnd - window_s) v.spread = std::max(v.spread, std::isfinite(y[i]) ? std::abs(y[i] - yEnd) : INFINITY);
  if (!(v.spread <= v.tolerance)) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s varies by %.3g over the last %g s (tolerance %.3g = %g |final| + %g)",
                  name.c_str(), v.spread, window_s, v.tolerance, rel_tol, abs_tol);
    v.reason = buf;
    return v;
  }
  v.steady = true;
  return v;
}

void checkRunTimes(const Given& tEnd, const Given& dt) {
  requireFinite(tEnd.value, tEnd.name);
  if (!(tEnd.value > 0) || tEnd.value > 1e5)
    throw Error(tEnd.name + " must lie in (0, 1e5] s, got " + formatValue(tEnd.value));
  requireFinite(dt.value, dt.name);
  if (!(dt.value > 0)) throw Error(dt.name + " must be positive, got " + formatValue(dt.value));
  if (dt.value > tEnd.value)
    throw Error(dt.name + " (" + formatValue(dt.value) + " s) must not exceed the run's end time " + tEnd.name + " (" +
                formatValue(tEnd.value) + " s)");
  if (tEnd.value / dt.value > 1e6)
    throw Error(dt.name + " = " + formatValue(dt.value) + " s gives " + formatValue(std::ceil(tEnd.value / dt.value)) +
                " samples over " + formatValue(tEnd.value) + " s (limit 1e6; " + dt.name + " must be at least " +
                formatValue(tEnd.value / 1e6) + " s)");
}

void plot(const std::vector<PlotSpec>& plots) {
  for (const PlotSpec& p : plots) {
    vdyn::PlotSpec f;
    f.title = p.title, f.xlabel = p.xlabel, f.ylabel = p.ylabel;
    f.equal_axes = p.equal_axes, f.logx = p.logx, f.logy = p.logy, f.points = p.points;
    for (const Series& s : p.series) {
      vdyn::PlotSeries q{s.csv, s.x, s.y, s.label};
      q.style = s.style;
      std::size_t start = 0;
      while (!s.filter.empty() && start <= s.filter.size()) {
        const std::size_t end = std::min(s.filter.find(';', start), s.filter.size());
        const std::string term = s.filter.substr(start, end - start);
        const auto eq = term.find('=');
        if (eq == std::string::npos) throw Error("plot filter '" + s.filter + "': expected column=value terms");
        q.where.emplace_back(term.substr(0, eq), term.substr(eq + 1));
        start = end + 1;
      }
      f.series.push_back(q);
    }
    renderFigure(f, p.png, [](const std::string& csv) { return csv; });
  }
}

bool interactive() { return isatty(fileno(stderr)); }

std::function<void(const SimTK::State&)> progress(const std::string& label, double tEnd) {
  const bool tty = interactive();
  const auto start = std::chrono::steady_clock::now();
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(start);
  return [label, tEnd, last, tty, start](const SimTK::State& s) {
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - *last).count() < (tty ? 0.2 : 10.0)) return;
    *last = now;
    if (tty) {
      std::fprintf(stderr, "\r%s: t = %.2f / %.2f s", label.c_str(), s.getTime(), tEnd);
    } else {  // a log: one line every 10 s of wall time
      std::fprintf(stderr, "%s: t = %.3f / %.3f s after %.0f s wall time\n", label.c_str(), s.getTime(), tEnd,
                   std::chrono::duration<double>(now - start).count());
    }
    std::fflush(stderr);
  };
}

void endProgress() {
  if (interactive()) std::fprintf(stderr, "\r\033[K");
}

void addIntegratorOptions(po::options_description& options) {
  std::string names;
  for (const auto& n : integratorNames()) names += (names.empty() ? "" : ", ") + n;
  options.add_options()("integrator", po::value<std::string>(), ("integrator: " + names).c_str())(
      "accuracy", po::value<double>(), "integrator relative accuracy (dimensionless)");
}

void applyIntegratorOptions(const po::variables_map& vm, IntegratorSettings& settings) {
  if (vm.count("integrator")) settings.method = vm["integrator"].as<std::string>();
  if (vm.count("accuracy")) {
    settings.accuracy = requireFinite(vm["accuracy"].as<double>(), "--accuracy");
    if (!(settings.accuracy > 0 && settings.accuracy < 1))
      throw Error("--accuracy must lie in (0, 1), got " + formatValue(settings.accuracy));
  }
  settings.validate();
}

}  // namespace vdyn::study
