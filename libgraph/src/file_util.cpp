// SPDX-License-Identifier: MIT
// Whole-file reads and all-or-nothing writes (an unnamed or temporary file, then a rename in
// the same folder).
#include "tgraph/graph/file_util.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <ctime>
#include <cstring>
#include <filesystem>
#include <string>

#include "fd_write.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph {
namespace {

std::string errno_text(int err) { return std::strerror(err); }

// The folder an output's temporary or unnamed file goes to: the output's own.
std::filesystem::path folder_of(const std::filesystem::path& target) {
  return target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
}

// The temporary name of an output in its folder: ".NAME.tmp.TAIL".
std::string temporary_name(const std::filesystem::path& target, const char* tail) {
  std::string name(".");
  name += target.filename().string();
  name += ".tmp.";
  name += tail;
  return (folder_of(target) / name).string();
}

// Gives the unnamed file `fd` the new name `path` (fails with EEXIST if it exists): through
// /proc/self/fd, else linkat(AT_EMPTY_PATH) where the process may use it.
bool link_unnamed(int fd, const std::string& path) {
  const std::string self = "/proc/self/fd/" + std::to_string(fd);
  if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, path.c_str(), AT_SYMLINK_FOLLOW) == 0)
    return true;
#ifdef AT_EMPTY_PATH
  if (errno != EEXIST && ::linkat(fd, "", AT_FDCWD, path.c_str(), AT_EMPTY_PATH) == 0) return true;
#endif
  return false;
}

// Closes a descriptor on scope exit unless released.
class FdGuard {
 public:
  explicit FdGuard(int fd) : fd_(fd) {}
  ~FdGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_;
};

}  // namespace

std::vector<std::uint8_t> read_file_bytes(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path, std::nullopt, "cannot open: " + errno_text(errno));
  FdGuard guard(fd);
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw InputError(path, std::nullopt, "cannot stat: " + errno_text(errno));
  if (S_ISDIR(st.st_mode)) throw InputError(path, std::nullopt, "cannot read: is a directory");
  // Regular files: one allocation of the right size (+1 to see the end of file without
  // growing). Pipes and devices: grow by doubling as read.
  std::vector<std::uint8_t> bytes(S_ISREG(st.st_mode) ? static_cast<std::size_t>(st.st_size) + 1
                                                      : std::size_t{65536});
  std::size_t size = 0;
  for (;;) {
    if (size == bytes.size()) bytes.resize(bytes.size() * 2);
    const ::ssize_t n = ::read(fd, bytes.data() + size, bytes.size() - size);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(path, size, "cannot read: " + errno_text(errno));
    }
    if (n == 0) break;
    size += static_cast<std::size_t>(n);
  }
  bytes.resize(size);
  return bytes;
}

std::string read_file_text(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return std::string(bytes.begin(), bytes.end());
}

namespace detail {

void write_all(int fd, std::string_view bytes, const std::string& name) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ::ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(name + ": cannot write: " + errno_text(errno));
    }
    done += static_cast<std::size_t>(n);
  }
}

void sync_close_rename(int fd, const std::string& from, const std::string& to,
                       const std::string& name, const std::string& from_label) {
  if (::fsync(fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(fd);
    throw Error(name + ": cannot sync: " + errno_text(err));
  }
  if (::close(fd) != 0) throw Error(name + ": cannot close: " + errno_text(errno));
  if (::rename(from.c_str(), to.c_str()) != 0)
    throw Error(to + ": cannot rename " + from_label + " into place: " + errno_text(errno));
}

int open_unnamed_beside(const std::string& path) {
#ifdef O_TMPFILE
  return ::open(folder_of(path).c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
#else
  (void)path;
  return -1;
#endif
}

bool name_unnamed(int fd, const std::string& path) {
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) return false;
  return link_unnamed(fd, path);
}

}  // namespace detail

namespace {

// The unnamed-file way of write_file_atomic: the bytes written and synced before the file
// has a name, then linked as ".NAME.tmp.<n>" and renamed over `path`, so that a process
// killed while it writes leaves nothing behind (only the two calls between link and rename
// can leave the temporary name). False where the file system has no unnamed files or /proc
// cannot link them, leaving nothing behind (an unnamed file already written is dropped with
// its descriptor; the caller then writes the bytes again the named way).
bool write_unnamed_then_rename(const std::string& path, std::string_view content) {
  const int fd = detail::open_unnamed_beside(path);
  if (fd < 0) return false;
  FdGuard guard(fd);
  ::fchmod(fd, 0644);  // as the named way: ordinary readable files, whatever the umask
  detail::write_all(fd, content, path);
  if (::fsync(fd) != 0 && errno != EINVAL) throw Error(path + ": cannot sync: " + errno_text(errno));
  const std::filesystem::path target(path);
  static std::atomic<std::uint64_t> serial{0};
  for (int attempt = 0; attempt < 64; ++attempt) {
    const std::uint64_t n = (static_cast<std::uint64_t>(::getpid()) << 40) ^
                            (static_cast<std::uint64_t>(::time(nullptr)) << 20) ^
                            serial.fetch_add(1, std::memory_order_relaxed);
    char suffix[24];
    std::snprintf(suffix, sizeof suffix, "%016llx", static_cast<unsigned long long>(n));
    const std::string tmp = temporary_name(target, suffix);
    if (!link_unnamed(fd, tmp)) {
      if (errno == EEXIST) continue;
      return false;  // no /proc, or links refused: the named way
    }
    if (::close(guard.release()) != 0) {
      const int err = errno;
      ::unlink(tmp.c_str());
      throw Error(path + ": cannot close: " + errno_text(err));
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
      const int err = errno;
      ::unlink(tmp.c_str());
      throw Error(path + ": cannot rename the temporary file into place: " + errno_text(err));
    }
    return true;
  }
  return false;
}

}  // namespace

void write_file_atomic(const std::string& path, std::string_view content) {
  if (write_unnamed_then_rename(path, content)) return;
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::string tmp = temporary_name(target, "XXXXXX");
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0)
    throw Error(path + ": cannot create a temporary file in its folder: " + errno_text(errno));
  FdGuard guard(fd);
  ::fchmod(fd, 0644);  // mkstemp creates 0600; outputs are ordinary readable files
  try {
    detail::write_all(fd, content, path);
    detail::sync_close_rename(guard.release(), tmp, path, path, "the temporary file");
  } catch (...) {
    ::unlink(tmp.c_str());
    throw;
  }
}

void write_output(const std::string& path, std::string_view content) {
  if (!path.empty() && path != "-") return write_file_atomic(path, content);
  std::fwrite(content.data(), 1, content.size(), stdout);
  std::fflush(stdout);
}

}  // namespace tgraph
