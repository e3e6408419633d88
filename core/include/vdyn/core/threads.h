#pragma once
// What runs in several threads at once (the sweep runner, ch6_steering_ratio)
// must not share mutable state. Each run builds its own Scene, System and
// State; the plugin registry is built once (a function-local static) and only
// read afterwards. One thing in Debian's Simbody 3.7 is not thread-safe:
// SimTK::Assembler solves with Simbody's bundled Ipopt, whose objects take
// their cache tags from one unsynchronized global counter (and whose option
// registration writes globals); valgrind --tool=helgrind reports races between
// two assemblies in two threads, and a lost tag update can make Ipopt reuse a
// stale cached result. Every Assembler::assemble() call therefore holds this
// process-wide lock (assembly is a small part of a run).
#include <mutex>

namespace vdyn {

inline std::unique_lock<std::mutex> lockSimbodyAssembler() {
  static std::mutex m;
  return std::unique_lock<std::mutex>(m);
}

}  // namespace vdyn
