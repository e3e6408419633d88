#include "vdyn/core/file_io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "vdyn/core/error.h"

namespace vdyn {

namespace {
/// Writes all of [p, p + n) to fd; returns 0 or the errno of the failed write.
int writeAll(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (w == 0) return EIO;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return 0;
}

/// fsync reports a deferred write error (a full disk on some file systems);
/// EINVAL/EROFS: the target (a device such as /dev/null) does not support it.
int syncFd(int fd) {
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) return errno;
  return 0;
}
}  // namespace

void writeFileAtomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("cannot write '" + path + "': " + std::strerror(errno) + " (nothing written)");
  auto fail = [&](const char* what, int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw Error("cannot write '" + path + "': " + what + ": " + std::strerror(err) + " (nothing written)");
  };
  if (const int err = writeAll(fd, text.data(), text.size())) fail("write failed", err);
  if (const int err = syncFd(fd)) fail("fsync failed", err);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw Error("cannot write '" + path + "': close failed: " + std::strerror(err) + " (nothing written)");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw Error("cannot write '" + path + "': rename from '" + tmp + "' failed: " + std::strerror(err) +
                " (nothing written)");
  }
}

AppendFile::AppendFile(const std::string& path, bool append) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0644);
  if (fd_ < 0) throw Error("cannot write '" + path + "': " + std::strerror(errno));
  if (!append) return;
  // A line cut before its line break (a kill between the two) is closed first.
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && st.st_size > 0) {
    char last = '\n';
    if (::pread(fd_, &last, 1, st.st_size - 1) == 1 && last != '\n') {
      if (const int err = writeAll(fd_, "\n", 1)) {
        ::close(fd_);
        fd_ = -1;
        throw Error("cannot append to '" + path + "': " + std::strerror(err));
      }
    }
  }
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

void AppendFile::appendLine(const std::string& line) {
  if (fd_ < 0) throw Error("cannot append to '" + path_ + "': the file is closed");
  const std::string text = line + "\n";
  if (const int err = writeAll(fd_, text.data(), text.size()))
    throw Error("cannot append to '" + path_ + "': write failed: " + std::strerror(err));
  if (const int err = syncFd(fd_)) throw Error("cannot append to '" + path_ + "': fsync failed: " + std::strerror(err));
}

void AppendFile::close() {
  if (fd_ < 0) return;
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw Error("cannot append to '" + path_ + "': close failed: " + std::strerror(errno));
}

}  // namespace vdyn
