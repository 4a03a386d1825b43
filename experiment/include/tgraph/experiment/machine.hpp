// SPDX-License-Identifier: MIT
// The machine an experiment runs on, as hwloc and /proc/cpuinfo describe it.
#pragma once

#include <cstdint>
#include <string>

namespace tgraph::experiment {

/// What the results need to say about the machine.
struct MachineInfo {
  std::string model;           ///< CPU model name ("" when unknown)
  std::uint32_t cores = 1;     ///< physical cores (hwloc), the measured thread counts' limit
  std::uint32_t pus = 1;       ///< hardware threads (hwloc processing units)
  std::uint32_t packages = 1;  ///< sockets
  std::uint32_t numa_nodes = 1;
  std::uint64_t l2_bytes = 0;  ///< first L2 cache (0: unknown)
  std::uint64_t l3_bytes = 0;  ///< first L3 cache (0: unknown)
  std::string os;              ///< kernel name and release (uname)
  /// "AMD EPYC, 2 cores (2 hardware threads), 1 socket, 1 NUMA node, L2 1 MiB, L3 32 MiB".
  std::string summary() const;
};

/// Probes this machine (hwloc topology; std::thread::hardware_concurrency when hwloc fails).
MachineInfo probe_machine();

}  // namespace tgraph::experiment
