#include "vdyn/vehicles/assembly.h"

#include "vdyn/core/error.h"
#include "vdyn/core/threads.h"

namespace vdyn {

void assembleLoops(const SimTK::MultibodySystem& system, SimTK::State& s,
                   const std::vector<SimTK::MobilizedBodyIndex>& locked,
                   const std::vector<std::pair<std::string, SimTK::MobilizedBody>>& bodies, double initialGap,
                   const std::string& what, AssemblyReport* report) {
  system.realize(s, SimTK::Stage::Position);
  std::vector<SimTK::Vec3> before;
  for (const auto& b : bodies) before.push_back(b.second.getBodyOriginLocation(s));
  SimTK::Assembler assembler(system);
  for (auto mbx : locked) assembler.lockMobilizer(mbx);
  assembler.setErrorTolerance(1e-10);
  try {
    const auto lock = lockSimbodyAssembler();  // Simbody's Ipopt is not thread-safe (vdyn/core/threads.h)
    assembler.assemble(s);
  } catch (const std::exception& e) {
    throw Error(what + ": closing the suspension loops failed: " + e.what());
  }
  system.realize(s, SimTK::Stage::Position);
  if (!report) return;
  report->initial_loop_gap_m = initialGap;
  report->body_moves_m.clear();
  report->max_move_m = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const double d = (bodies[i].second.getBodyOriginLocation(s) - before[i]).norm();
    report->body_moves_m.emplace_back(bodies[i].first, d);
    report->max_move_m = std::max(report->max_move_m, d);
  }
}

}  // namespace vdyn
