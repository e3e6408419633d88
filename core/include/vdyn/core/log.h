#pragma once
// Diagnostics from the libraries (solver iterations, grid refinement): a
// severity and a sink that the program using them installs. No sink is
// installed by default: nothing is printed and no message is formatted
// (logEnabled() is false). Logging never changes a result; settings keys
// choose algorithms, never the log or the environment.
//
// Threads: install the sink once before any run (the vdyn program does so for
// --verbose while it reads its options). The sink is held through an atomic
// shared pointer, so installing it while a run logs does not race (the run
// may use the old or the new one), and a sink must be safe to call from
// several threads at once (stderrLogSink() writes each message with one call).
#include <functional>
#include <string>

namespace vdyn {

enum class LogLevel { Debug = 0, Info = 1, Warning = 2 };

/// "debug", "info", "warning".
const char* logLevelName(LogLevel level);

/// Receives each message at or above the installed minimum level.
using LogSink = std::function<void(LogLevel, const std::string&)>;

/// Installs `sink` for messages at `minimum` and above; an empty sink turns
/// logging off (the default).
void setLogSink(LogSink sink, LogLevel minimum = LogLevel::Debug);
/// True if a message at `level` would reach a sink: callers test it before
/// formatting a message.
bool logEnabled(LogLevel level);
/// Sends `message` to the sink if logEnabled(level).
void logMessage(LogLevel level, const std::string& message);
/// printf-style formatting for log messages.
std::string logFormat(const char* format, ...) __attribute__((format(printf, 1, 2)));

/// A sink writing "vdyn <level>: <message>\n" to stderr, one write per message.
LogSink stderrLogSink();

}  // namespace vdyn
