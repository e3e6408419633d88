#pragma once
// SIGINT and SIGTERM as a request to stop at the next safe point: the handler
// only records the signal; long loops (a simulation's steps, a sweep's
// variations) poll it and end with an Interrupted error after writing what is
// complete. A second signal ends the program at once (the default action).
#include <string>

#include "vdyn/core/error.h"

namespace vdyn {

/// The run stopped at a safe point because of a signal; the program exits
/// 128 + signal() (130 for SIGINT).
class Interrupted : public Error {
 public:
  Interrupted(int signal, const std::string& what) : Error(what), signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// Installs the handlers for SIGINT and SIGTERM (idempotent).
void installInterruptHandlers();
/// The signal received since installInterruptHandlers(), or 0.
int interruptSignal();
/// "SIGINT", "SIGTERM" or "signal N".
std::string signalName(int signal);
/// Throws Interrupted("interrupted by SIGINT <where>") if a signal arrived.
void throwIfInterrupted(const std::string& where);
/// Records `signal` as if it had arrived (tests); 0 clears it.
void setInterruptSignal(int signal);

}  // namespace vdyn
