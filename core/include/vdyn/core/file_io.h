#pragma once
// The one way vdyn writes a file: every output (summaries, tables, journals,
// plot data and gnuplot scripts) goes through these two.
#include <sstream>
#include <string>
#include <utility>

namespace vdyn {

/// Writes `text` to "<path>.tmp" in the same folder, checks every write, the
/// fsync and the close (a full disk or an unwritable folder is an Error naming
/// the file and the system's reason, ending "(nothing written)"), then renames
/// it to `path`. On failure the temporary file is removed and `path` is left as
/// it was: an output file is complete or absent, never half-written.
void writeFileAtomic(const std::string& path, const std::string& text);

/// Text collected in memory (a std::ostringstream) and written by
/// writeFileAtomic on commit(): a file whose writer throws before commit() is
/// not written at all.
class OutputFile : public std::ostringstream {
 public:
  explicit OutputFile(std::string path) : path_(std::move(path)) {}
  void commit() const { writeFileAtomic(path_, str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// An append-only log (a sweep's journal, runs.jsonl): each appendLine is one
/// checked write of a whole line followed by an fsync, so a line is on disk
/// before the caller counts it as done. A failure is an Error naming the file
/// and the system's reason. A line cut by a kill before its line break is
/// closed when the file is opened for appending.
class AppendFile {
 public:
  AppendFile(const std::string& path, bool append);
  ~AppendFile();
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  /// Appends `line` and a line break (one write), then fsyncs.
  void appendLine(const std::string& line);
  /// Closes the file, checking the close (the destructor closes silently).
  void close();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace vdyn
