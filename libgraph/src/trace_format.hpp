// SPDX-License-Identifier: MIT
// Internal: the .tgt trace format's framing, shared by the writer (trace_write.cpp) and the
// reader (trace_read.cpp); docs/trace-format.md describes it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::detail {

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'G', 'T', 'R'};
constexpr std::uint32_t kFormatVersion = 2;
// Version 1 lacks the step's host time (StepGraph::host_ns, read as 0); still read.
constexpr std::uint32_t kOldestFormatVersion = 1;
constexpr std::size_t kFileHeaderSize = 8;    // magic + u32 version
constexpr std::size_t kFrameHeaderSize = 12;  // u32 type + u32 length + u32 crc

enum class FrameType : std::uint32_t { Header = 1, FullStep = 2, ReferenceStep = 3, End = 4 };

/// The structure section of `step` (what same_structure() compares and a reference frame
/// repeats): kinds, objects, data, tasks, accesses, loops; no edges, costs or contacts.
inline StepGraph structure_of(const StepGraph& step) {
  StepGraph shape;
  shape.kinds = step.kinds;
  shape.objects = step.objects;
  shape.data = step.data;
  shape.tasks = step.tasks;
  shape.accesses = step.accesses;
  shape.loops = step.loops;
  return shape;
}

}  // namespace tgraph::detail
