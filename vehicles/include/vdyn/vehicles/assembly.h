#pragma once
// Closing the suspension loops from the tabulated configuration (the App. A
// positions do not close them exactly) and reporting how far the bodies moved.
#include <string>
#include <utility>
#include <vector>

#include <Simbody.h>

namespace vdyn {

/// How far the bodies moved when the loops were closed.
struct AssemblyReport {
  std::vector<std::pair<std::string, double>> body_moves_m;  ///< body name -> |displacement of origin|
  double max_move_m = 0;
  double initial_loop_gap_m = 0;  ///< largest cut-joint point separation before assembly
};

/// Assembles `s` (position constraints satisfied to 1e-10) holding the `locked`
/// mobilizers, then fills `report` (if given) with the displacement of each of
/// `bodies` and `initialGap`. Throws Error naming `what` if assembly fails.
void assembleLoops(const SimTK::MultibodySystem& system, SimTK::State& s,
                   const std::vector<SimTK::MobilizedBodyIndex>& locked,
                   const std::vector<std::pair<std::string, SimTK::MobilizedBody>>& bodies, double initialGap,
                   const std::string& what, AssemblyReport* report);

}  // namespace vdyn
