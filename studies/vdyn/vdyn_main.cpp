// vdyn: one program for scene files.
//   vdyn run SCENE [--set key.path=value ...] [--out DIR] [--plugin PATH ...]
//   vdyn check SCENE [--set ...] [--plugin PATH ...]
//   vdyn list [NAME] [--plugin PATH ...]   (NAME: a kind, a choice family or a type name)
//   vdyn sweep SWEEP [--threads N] [--out DIR] ...; mpirun -n N vdyn sweep SWEEP --mpi
//   vdyn tire TIRE_DATA [--fz N,...] [--alpha DEG,...] [--kappa ...] [--gamma DEG,...] [--out DIR]
// One source file per subcommand (run_command.cpp, check_command.cpp, list_command.cpp, sweep_command.cpp), listed in the
// table below.
#include <cstdio>
#include <iostream>

#include "command.h"
#include "vdyn/core/log.h"
#include "vdyn/core/plugin_library.h"
#include "vdyn/vehicles/standard_registry.h"

namespace vdyn::cli {

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"run", "run SCENE [--set key.path=value ...] [--out DIR] [--plugin PATH ...]",
       "load a scene file, run its analysis, write summary.json and tables to --out (default ./results/<scene>)",
       &runCommand},
      {"check", "check SCENE [--set key.path=value ...] [--plugin PATH ...]",
       "validate a scene file without running it; prints every error found", &checkCommand},
      {"list", "list [NAME] [--plugin PATH ...]; list outputs|attachments SCENE",
       "every registered vehicle, plugin and analysis with its keys, units, defaults and meaning", &listCommand},
      {"sweep", "sweep SWEEP [--threads N] [--out DIR] [--fresh] [--retry-failed] [--plugin PATH ...]; "
                "mpirun -n N vdyn sweep SWEEP --mpi",
       "run a scene over a sweep file's variations on threads or MPI processes; one CSV/JSON ordered by variation",
       &sweepCommand},
      {"tire", "tire TIRE_DATA [--fz N,...] [--alpha DEG,...] [--kappa K,...] [--gamma DEG,...] [--vx M_S] [--out DIR] "
               "[--no-plots] [--plugin PATH ...]",
       "any registered tire on its own in steady state: CSV of forces and moments over a grid, and the plots "
       "Fy-alpha, Mz-alpha, Fx-kappa and the friction ellipse", &tireCommand},
  };
  return table;
}

const Command& command(const std::string& name) {
  for (const auto& c : commands())
    if (name == c.name) return c;
  std::string list;
  for (const auto& c : commands()) list += (list.empty() ? "" : ", ") + std::string(c.name);
  throw Error("unknown command '" + name + "'; known: " + list);
}

void addCommonOptions(study::po::options_description& opts) {
  opts.add_options()("help,h", "print this help and exit")(
      "verbose", "print the libraries' diagnostics (solver iterations, sensitivity passes) to stderr")(
      "plugin", study::po::value<std::vector<std::string>>()->composing(),
      "load an out-of-tree plugin library (repeatable; see vdyn/core/plugin_library.h)");
}

bool parseArgs(const Command& cmd, const std::vector<std::string>& args, study::po::options_description& opts,
               const std::vector<std::string>& positional, study::po::variables_map& vm) {
  namespace po = study::po;
  po::positional_options_description pos;
  for (const auto& p : positional) pos.add(p.c_str(), 1);
  try {
    po::store(po::command_line_parser(args).options(opts).positional(pos).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    throw Error(std::string("bad command line: ") + e.what() + " (see vdyn " + cmd.name + " --help)");
  }
  // The log sink is installed once, here, before anything runs (vdyn/core/log.h).
  if (vm.count("verbose")) setLogSink(stderrLogSink());
  if (vm.count("help")) {
    std::cout << "vdyn " << cmd.usage << "\n  " << cmd.summary << "\n\n" << opts << std::endl;
    return false;
  }
  return true;
}

PluginRegistry& registryWithPlugins(const study::po::variables_map& vm) {
  PluginRegistry& r = standardRegistry();
  if (vm.count("plugin"))
    for (const auto& p : vm["plugin"].as<std::vector<std::string>>()) loadPluginLibrary(p, r);
  return r;
}

}  // namespace vdyn::cli

int main(int argc, char** argv) {
  using namespace vdyn::cli;
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cout << "vdyn: multibody vehicle dynamics from scene files\n\nusage:\n";
    for (const auto& c : commands()) std::cout << "  vdyn " << c.usage << "\n      " << c.summary << "\n";
    return argc < 2 ? 1 : 0;
  }
  const std::string name = argv[1];
  std::vector<std::string> args(argv + 2, argv + argc);
  int code = 1;
  const int rc = vdyn::study::run("vdyn " + name, [&] { code = command(name).main(args); });
  return rc != 0 ? rc : code;
}
