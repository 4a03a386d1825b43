// SPDX-License-Identifier: MIT
// Reading and writing .tgt trace files (format: docs/trace-format.md).
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tgraph/graph/trace.hpp"

namespace tgraph {

/// Options of the trace reader.
struct ReadOptions {
  /// Accept a trace whose last frame is cut short (capture killed): return the complete
  /// steps before it instead of failing.
  bool recover = false;
};

/// Options of write_trace and encode_trace.
struct WriteOptions {
  /// Store a step whose structure equals an earlier step's as a reference frame (the
  /// default, as TraceWriter does); false writes every step as a full frame (what a trace
  /// costs without the reuse: benchmarks and format tests).
  bool reuse_structure = true;
};

/// Streams steps to a .tgt file, one self-delimiting frame per step, each written with
/// write(2) before append() returns. The frames go to `<path>.partial`; close() writes the
/// end frame, syncs and renames it to `path`, so an existing file at `path` is replaced only
/// by a complete trace. A capture killed at any moment (or stopped by a failed write or a
/// diverging simulation) leaves `<path>.partial`, whose complete steps read back with
/// ReadOptions::recover (`tgraph info` reads X.partial so when asked to recover). Steps whose structure equals
/// an earlier step's are stored as a reference plus costs, loop counts and contacts.
///
///   TraceWriter w("run.tgt", header);   // writes run.tgt.partial
///   for (...) w.append(step);
///   w.close();                          // renames it to run.tgt
class TraceWriter {
 public:
  /// Creates (truncates) `<path>.partial` and writes the header frame. Throws tgraph::Error.
  TraceWriter(const std::string& path, const TraceHeader& header);
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;
  /// Appends one step (edges need not be derived; they are not stored). After a failed
  /// write (tgraph::Error) the partial file ends at the last complete frame and further
  /// appends throw UsageError.
  void append(const StepGraph& step);
  /// Writes the end frame, syncs and renames the partial file to the path.
  void close();
  /// Bytes written so far.
  std::uint64_t bytes_written() const;
  /// `<path>.partial`: where the frames are until close().
  const std::string& partial_path() const;
  /// Steps appended so far (complete frames in the partial file).
  std::uint32_t steps_written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a whole trace; edges of every step are derived. Throws InputError naming the file
/// and offset for any malformed input; never crashes, hangs or allocates without bound.
Trace read_trace(const std::string& path, const ReadOptions& options = {});
/// Same from bytes in memory; `name` is used in error messages.
Trace read_trace_bytes(std::span<const std::uint8_t> bytes, const std::string& name,
                       const ReadOptions& options = {});
/// Writes a whole trace (to a temporary file renamed into place).
void write_trace(const std::string& path, const Trace& trace, const WriteOptions& options = {});
/// Encodes a whole trace into bytes (what write_trace writes).
std::vector<std::uint8_t> encode_trace(const Trace& trace, const WriteOptions& options = {});

}  // namespace tgraph
