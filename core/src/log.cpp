#include "vdyn/core/log.h"

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <memory>

namespace vdyn {

namespace {
struct Installed {
  LogSink sink;
  LogLevel minimum;
};
// Read and replaced with the atomic shared_ptr functions: no lock, no race.
std::shared_ptr<const Installed> g_installed;
}  // namespace

const char* logLevelName(LogLevel level) {
  switch (level) {
    case LogLevel::Debug: return "debug";
    case LogLevel::Info: return "info";
    case LogLevel::Warning: return "warning";
  }
  return "?";
}

void setLogSink(LogSink sink, LogLevel minimum) {
  std::shared_ptr<const Installed> next;
  if (sink) next = std::make_shared<const Installed>(Installed{std::move(sink), minimum});
  std::atomic_store(&g_installed, next);
}

bool logEnabled(LogLevel level) {
  const auto in = std::atomic_load(&g_installed);
  return in && level >= in->minimum;
}

void logMessage(LogLevel level, const std::string& message) {
  const auto in = std::atomic_load(&g_installed);
  if (in && level >= in->minimum) in->sink(level, message);
}

std::string logFormat(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string s(n > 0 ? std::size_t(n) : 0, '\0');
  if (n > 0) std::vsnprintf(&s[0], std::size_t(n) + 1, format, args);
  va_end(args);
  return s;
}

LogSink stderrLogSink() {
  return [](LogLevel level, const std::string& message) {
    const std::string line = std::string("vdyn ") + logLevelName(level) + ": " + message + "\n";
    std::fwrite(line.data(), 1, line.size(), stderr);
  };
}

}  // namespace vdyn
