#pragma once
// Output files that are complete or absent, never half-written.
#include <string>

namespace vdyn {

/// Writes `text` to "<path>.tmp", checks every write and the close (a full
/// disk or an unwritable folder is an Error naming the file and the system's
/// reason), then renames it to `path`. On failure the temporary file is removed
/// and `path` is left as it was.
void writeFileAtomic(const std::string& path, const std::string& text);

}  // namespace vdyn
