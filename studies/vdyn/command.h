#pragma once
// The subcommands of the `vdyn` program (CONTRACTS.md item 4): one source file
// each, listed in the table in vdyn_main.cpp. A new subcommand is one more file and
// one more table line.
#include <string>
#include <vector>

#include "study.h"
#include "vdyn/core/registry.h"

namespace vdyn::cli {

struct Command {
  const char* name;
  const char* usage;    ///< e.g. "run SCENE [--set key.path=value ...] [--out DIR] [--plugin PATH]"
  const char* summary;  ///< one line
  /// Runs with the arguments after the subcommand name; returns the exit code.
  /// Throws Error for a user error (printed as "vdyn <name>: error: ..." with exit 1).
  int (*main)(const std::vector<std::string>& args);
};

/// Adds --plugin PATH (repeatable), --verbose (a stderr log sink, installed by parseArgs) and --help.
void addCommonOptions(study::po::options_description& opts);
/// Parses `args` against `opts` with `positional` names (each once, in order);
/// on --help prints the usage and returns false.
bool parseArgs(const Command& cmd, const std::vector<std::string>& args, study::po::options_description& opts,
               const std::vector<std::string>& positional, study::po::variables_map& vm);
/// The registry every subcommand uses (standardRegistry) with the --plugin libraries loaded.
PluginRegistry& registryWithPlugins(const study::po::variables_map& vm);

// The subcommands.
int runCommand(const std::vector<std::string>& args);
int checkCommand(const std::vector<std::string>& args);
int listCommand(const std::vector<std::string>& args);
int sweepCommand(const std::vector<std::string>& args);
int tireCommand(const std::vector<std::string>& args);

/// The command table (vdyn_main.cpp).
const std::vector<Command>& commands();
const Command& command(const std::string& name);

}  // namespace vdyn::cli
