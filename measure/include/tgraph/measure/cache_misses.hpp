// SPDX-License-Identifier: MIT
// The hardware cache-miss counter a replay reports (perf_event_open).
#pragma once

#include <cstdint>
#include <string>

namespace tgraph::measure {

/// Hardware cache-miss counter of this process's threads (perf_event_open), where the
/// kernel allows it.
class CacheMissCounter {
 public:
  /// Opens the counter (inherit: threads created afterwards are counted too).
  CacheMissCounter();
  ~CacheMissCounter();
  CacheMissCounter(const CacheMissCounter&) = delete;
  CacheMissCounter& operator=(const CacheMissCounter&) = delete;
  /// False where the kernel refused (containers, VMs without PMU): not a failure, the
  /// reports say so in place of the count.
  bool available() const { return fd_ >= 0; }
  /// Why it is unavailable ("not counted: the kernel refused ... (errno text)"), empty when
  /// available.
  const std::string& reason() const { return reason_; }
  /// Misses counted so far (0 when unavailable).
  std::uint64_t read() const;

 private:
  int fd_ = -1;
  std::string reason_;
};

}  // namespace tgraph::measure
