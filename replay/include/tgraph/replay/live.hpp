// SPDX-License-Identifier: MIT
// Live replay: the engine's own task bodies (recorded in deferred mode) run by an executor,
// and the bit-for-bit comparison of final states.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tgraph/replay/workload.hpp"

namespace tgraph::replay {

/// Runs the bodies and loop conditions of a deferred step (capture::StepProgram's
/// `bodies` and `conditions`). Use CwMode::kSerialize: the bodies write through their own
/// pointers, so cross-thread CW writers are ordered as in the program (bit-identical).
class ProgramWorkload : public Workload {
 public:
  ProgramWorkload(std::span<const std::function<void()>> bodies,
                  std::span<const std::function<bool()>> conditions)
      : bodies_(bodies), conditions_(conditions) {}
  void run(const TaskRun& r) override;
  bool stop_after(LoopId loop, std::uint32_t iteration) override;

 private:
  std::span<const std::function<void()>> bodies_;
  std::span<const std::function<bool()>> conditions_;
};

/// One named piece of state (a datum's storage).
struct StateRegion {
  std::string name;
  const void* ptr = nullptr;
  std::uint64_t bytes = 0;
};

/// A copy of the bytes of some regions.
struct StateSnapshot {
  std::vector<std::string> names;
  std::vector<std::vector<std::uint8_t>> bytes;
};

/// Copies the regions' bytes.
StateSnapshot snapshot(std::span<const StateRegion> regions);

/// First difference between two snapshots of the same regions.
struct StateDifference {
  std::string datum;                  ///< name of the first differing region
  std::uint64_t offset = 0;           ///< first differing byte in it
  std::uint64_t differing_bytes = 0;  ///< in that region
};

/// nullopt when equal bit for bit.
std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual);

}  // namespace tgraph::replay
