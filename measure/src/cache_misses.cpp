// SPDX-License-Identifier: MIT
#include "tgraph/measure/cache_misses.hpp"

#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace tgraph::measure {

CacheMissCounter::CacheMissCounter() {
  perf_event_attr attr;
  std::memset(&attr, 0, sizeof attr);
  attr.size = sizeof attr;
  attr.type = PERF_TYPE_HARDWARE;
  attr.config = PERF_COUNT_HW_CACHE_MISSES;
  attr.disabled = 0;
  attr.inherit = 1;
  attr.exclude_kernel = 1;
  attr.exclude_hv = 1;
  const long fd = syscall(SYS_perf_event_open, &attr, 0, -1, -1, 0);
  if (fd < 0) {
    reason_ = std::string(
                  "not counted: the kernel refused hardware performance counters "
                  "(perf_event_open: ") +
              std::strerror(errno) + ")";
    return;
  }
  fd_ = static_cast<int>(fd);
}

CacheMissCounter::~CacheMissCounter() {
  if (fd_ >= 0) close(fd_);
}

std::uint64_t CacheMissCounter::read() const {
  if (fd_ < 0) return 0;
  std::uint64_t v = 0;
  if (::read(fd_, &v, sizeof v) != static_cast<ssize_t>(sizeof v)) return 0;
  return v;
}

}  // namespace tgraph::measure
