#include "vdyn/core/interrupt.h"

#include <atomic>
#include <csignal>

namespace vdyn {

namespace {
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the handler needs a lock-free flag");

extern "C" void onInterrupt(int sig) {
  if (g_signal.exchange(sig) != 0) {  // the second signal: stop at once
    std::signal(sig, SIG_DFL);
    std::raise(sig);
  }
}
}  // namespace

void installInterruptHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;  // a blocking read or write resumes; loops poll the flag
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int interruptSignal() { return g_signal.load(); }

void setInterruptSignal(int signal) { g_signal.store(signal); }

std::string signalName(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

void throwIfInterrupted(const std::string& where) {
  if (const int sig = interruptSignal()) throw Interrupted(sig, "interrupted by " + signalName(sig) + " " + where);
}

}  // namespace vdyn
