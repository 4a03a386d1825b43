// SPDX-License-Identifier: MIT
// Reading and writing .tga assignment files (format: docs/assignment-format.md).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"

namespace tgraph::partition {

/// Current .tga format version.
inline constexpr std::uint32_t kAssignmentVersion = 1;

/// Encodes `a` (with per-step structural hashes, one per step or empty) as .tga bytes.
std::vector<std::uint8_t> encode_assignment(const TraceAssignment& a,
                                            const std::vector<std::uint64_t>& hashes = {});
/// Decodes .tga bytes; throws InputError naming `name` and the offset for any malformed
/// input (truncation, bad magic, version, checksum, k = 0, processor out of range, bad
/// order). `hashes` receives the stored structural hashes (0 where none was stored).
TraceAssignment decode_assignment(std::span<const std::uint8_t> bytes, const std::string& name,
                                  std::vector<std::uint64_t>* hashes = nullptr);
/// Writes a .tga file atomically.
void write_assignment(const std::string& path, const TraceAssignment& a,
                      const std::vector<std::uint64_t>& hashes = {});
/// Reads a .tga file.
TraceAssignment read_assignment(const std::string& path,
                                std::vector<std::uint64_t>* hashes = nullptr);

/// Writes the assignment of `trace`'s steps with their structural hashes (what partition_file
/// writes), so that load_assignment can tell a file made for another trace.
void write_assignment(const std::string& path, const TraceAssignment& a, const Trace& trace);
/// Reads the .tga file `path` and checks that it fits `trace` (named `trace_name` in
/// errors): check_fits (step and task counts, processors, orders) and, where the file stored
/// one, each step's structural hash. Throws InputError naming `path`.
TraceAssignment load_assignment(const std::string& path, const Trace& trace,
                                const std::string& trace_name);
/// load_assignment, or nullopt when `path` is empty (no assignment given).
std::optional<TraceAssignment> load_assignment_if(const std::string& path, const Trace& trace,
                                                  const std::string& trace_name);

/// What load_or_partition computed, when it partitioned (TracePartition's notes).
struct PartitionNotes {
  std::string method;     ///< the method run (the default_method when none was named)
  std::string placed_by;  ///< TracePartition::placed_by
  std::vector<std::string> warnings;  ///< TracePartition::warnings
};

/// The assignment `tgraph replay` runs on `k` threads: the .tga file `path` (checked against
/// `trace`, named `trace_name` in errors, as load_assignment does, and its K against `k`:
/// OptionError of the field "threads") or, when `path` is empty, `method` applied to every
/// step (default_method when `method` is empty), with what it did in `notes` when given.
/// OptionError of "threads" when `k` is 0.
TraceAssignment load_or_partition(const Trace& trace, const std::string& trace_name,
                                  const std::string& path, const std::string& method,
                                  std::uint32_t k, PartitionNotes* notes = nullptr);

/// Where load_or_partition's assignment came from, as `tgraph replay` reports it: the file
/// `path`, or the strategy that placed the steps and why that one ("owner (computed,
/// default)", "list (computed, fallback of owner)"...); `method` is the one the user named
/// (empty: none).
std::string assignment_label(const std::string& path, const std::string& method,
                             const PartitionNotes& notes);

}  // namespace tgraph::partition
