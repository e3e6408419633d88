#include "study.h"

#include <chrono>
#include <cstdio>
#include <memory>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <unistd.h>

namespace vdyn::study {

int run(const std::string& study, const std::function<void()>& body) {
  try {
    body();
    return 0;
  } catch (const std::exception& e) {
    std::string msg = e.what();
    for (auto& c : msg)
      if (c == '\n') c = ' ';
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
    po::store(po::parse_command_line(argc, argv, options), vm);
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
  return dir;
}

void writeJson(const std::string& path, const Json& j) {
  std::ofstream out(path);
  if (!out) throw Error("cannot write '" + path + "'");
  out << j.dump(2) << '\n';
}

static std::string quote(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

void plot(const std::vector<PlotSpec>& plots) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0)
    throw Error("gnuplot not found: the PNG plots need it (apt-get install gnuplot-nox)");
  for (const PlotSpec& p : plots) {
    const std::string script = p.png + ".gp";
    std::ofstream g(script);
    if (!g) throw Error("cannot write '" + script + "'");
    g << "set terminal pngcairo size 1000,650 font 'sans,10'\n"
      << "set output " << quote(p.png) << "\n"
      << "set datafile separator ','\nset key autotitle columnhead\nset grid\n"
      << "set title " << quote(p.title) << " noenhanced\n"
      << "set xlabel " << quote(p.xlabel) << " noenhanced\nset ylabel " << quote(p.ylabel) << " noenhanced\n"
      << "set key noenhanced\n";
    if (p.equal_axes) g << "set size ratio -1\n";
    if (p.logx) g << "set logscale x\nset format x '10^{%L}'\n";
    if (p.logy) g << "set logscale y\nset format y '10^{%L}'\n";
        g << "plot ";
    for (std::size_t i = 0; i < p.series.size(); ++i) {
      const Series& s = p.series[i];
      std::string y = "column(" + quote(s.y) + ")";
      if (!s.filter.empty()) {
        std::string cond;
        std::size_t start = 0;
        while (start <= s.filter.size()) {
          const std::size_t end = std::min(s.filter.find(';', start), s.filter.size());
          const std::string term = s.filter.substr(start, end - start);
          const auto eq = term.find('=');
          if (eq == std::string::npos) throw Error("plot filter '" + s.filter + "': expected column=value terms");
          cond += (cond.empty() ? "" : " && ") + std::string("strcol(") + quote(term.substr(0, eq)) + ") eq " +
                  quote(term.substr(eq + 1));
          start = end + 1;
        }
        y = "((" + cond + ") ? " + y + " : NaN)";
      }
      g << (i ? ", \\\n     " : "") << quote(s.csv) << " using (column(" << quote(s.x) << ")):(" << y << ")"
        << (p.points ? " with linespoints lw 2 pt 7 title " : " with lines lw 2 title ") << quote(s.label);
    }
    g << "\n";
    g.close();
    const std::string cmd = "gnuplot " + quote(script) + " 2> " + quote(p.png + ".log");
    if (std::system(cmd.c_str()) != 0) {
      std::ifstream log(p.png + ".log");
      std::string line, last;
      while (std::getline(log, line))
        if (!line.empty()) last = line;
      throw Error("gnuplot failed on '" + script + "': " + last);
    }
    std::remove((p.png + ".log").c_str());
  }
}

bool interactive() { return isatty(fileno(stderr)); }

std::function<void(const SimTK::State&)> progress(const std::string& label, double tEnd) {
  if (!interactive()) return {};
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  return [label, tEnd, last](const SimTK::State& s) {
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - *last).count() < 0.2) return;
    *last = now;
    std::fprintf(stderr, "\r%s: t = %.2f / %.2f s", label.c_str(), s.getTime(), tEnd);
    std::fflush(stderr);
  };
}

void endProgress() {
  if (interactive()) std::fprintf(stderr, "\r\033[K");
}

void addIntegratorOptions(po::options_description& options) {
  options.add_options()("integrator", po::value<std::string>(),
                        "integrator: rk_merson, rk3, rk_feldberg, cpodes, verlet, semi_explicit_euler2")(
      "accuracy", po::value<double>(), "integrator relative accuracy (dimensionless)");
}

void applyIntegratorOptions(const po::variables_map& vm, IntegratorSettings& settings) {
  if (vm.count("integrator")) settings.method = vm["integrator"].as<std::string>();
  if (vm.count("accuracy")) settings.accuracy = vm["accuracy"].as<double>();
}

}  // namespace vdyn::study
