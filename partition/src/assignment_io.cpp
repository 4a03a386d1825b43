// SPDX-License-Identifier: MIT
// The .tga file: see docs/assignment-format.md.
#include "tgraph/partition/assignment_io.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <string_view>

#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {

namespace {

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'G', 'A', 'S'};
constexpr std::size_t kHeaderBytes = 4 + 4 + 8;           // magic, version, total length
constexpr std::size_t kMinBytes = kHeaderBytes + 12 + 4;  // + k, steps, method length; crc
constexpr std::uint32_t kMaxMethod = 256;
constexpr std::uint32_t kMaxK = 1u << 20;
constexpr std::size_t kStepHeader = 4 + 8 + 8 + 1;  // tasks, hash, partition ms, has order

}  // namespace

std::vector<std::uint8_t> encode_assignment(const TraceAssignment& a,
                                            const std::vector<std::uint64_t>& hashes) {
  std::vector<std::uint8_t> out;
  ByteWriter w(out);
  w.bytes(std::string_view(reinterpret_cast<const char*>(kMagic.data()), kMagic.size()));
  w.u32(kAssignmentVersion);
  w.u64(0);  // total length, patched below
  w.u32(a.k);
  w.u32(static_cast<std::uint32_t>(a.steps.size()));
  const std::string_view method = std::string_view(a.method).substr(0, kMaxMethod);
  w.u32(static_cast<std::uint32_t>(method.size()));
  w.bytes(method);
  for (std::size_t s = 0; s < a.steps.size(); ++s) {
    const Assignment& as = a.steps[s];
    w.u32(static_cast<std::uint32_t>(as.proc.size()));
    w.u64(s < hashes.size() ? hashes[s] : 0);
    w.f64(s < a.partition_ms.size() ? a.partition_ms[s] : 0.0);
    w.u8(as.order.empty() ? 0 : 1);
    for (ProcId p : as.proc) w.u32(p);
    if (!as.order.empty())
      for (std::uint32_t p = 0; p < a.k; ++p) {
        const std::vector<TaskId> none;
        const std::vector<TaskId>& o = p < as.order.size() ? as.order[p] : none;
        w.u32(static_cast<std::uint32_t>(o.size()));
        for (TaskId t : o) w.u32(t);
      }
  }
  w.u64_at(8, out.size() + 4);
  w.u32(crc32(out));
  return out;
}

TraceAssignment decode_assignment(std::span<const std::uint8_t> bytes, const std::string& name,
                                  std::vector<std::uint64_t>* hashes) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic.data(), 4) != 0)
    throw InputError(name, 0, "expected magic \"TGAS\" (not a .tga assignment file)");
  if (bytes.size() < kMinBytes)
    throw InputError(
        name, bytes.size(),
        "truncated: expected a header of at least " + std::to_string(kMinBytes) + " bytes");
  ByteReader head(bytes, 0, bytes.size(), name, "the file");
  head.u32("magic");
  const std::uint32_t version = head.u32("version");
  if (version != kAssignmentVersion)
    head.fail(4, "unsupported version " + std::to_string(version) + " (expected " +
                     std::to_string(kAssignmentVersion) + ")");
  const std::uint64_t total = head.u64("total length");
  if (total > bytes.size())
    throw InputError(name, bytes.size(),
                     "truncated: header says " + std::to_string(total) + " bytes, file has " +
                         std::to_string(bytes.size()));
  if (total < bytes.size())
    throw InputError(name, total, "expected end of file after " + std::to_string(total) + " bytes");
  const std::uint32_t stored_crc =
      ByteReader(bytes, bytes.size() - 4, bytes.size(), name, "the file").u32("checksum");
  if (crc32(bytes.first(bytes.size() - 4)) != stored_crc)
    throw InputError(name, bytes.size() - 4, "checksum mismatch (file corrupted)");

  ByteReader r(bytes, kHeaderBytes, bytes.size() - 4, name, "the file");
  TraceAssignment a;
  const std::size_t k_at = r.pos();
  a.k = r.u32("k");
  if (a.k == 0 || a.k > kMaxK)
    r.fail(k_at, "expected k in [1, " + std::to_string(kMaxK) + "], got " + std::to_string(a.k));
  const std::uint32_t steps = r.u32("step count");
  const std::uint32_t method_len = r.u32("method length");
  if (method_len > kMaxMethod)
    r.fail(r.pos() - 4, "expected a method name of at most " + std::to_string(kMaxMethod) +
                            " bytes, found length " + std::to_string(method_len));
  a.method = r.bytes(method_len, "method name");
  if (steps > r.left() / kStepHeader)
    r.fail(r.pos(), "step count " + std::to_string(steps) + " exceeds the file: expected at most " +
                        std::to_string(r.left() / kStepHeader) + " steps in the " +
                        std::to_string(r.left()) + " bytes left");
  a.steps.resize(steps);
  a.partition_ms.resize(steps);
  if (hashes != nullptr) hashes->assign(steps, 0);
  for (std::uint32_t s = 0; s < steps; ++s) {
    const std::string where = "step " + std::to_string(s) + ": ";
    Assignment& as = a.steps[s];
    as.k = a.k;
    const std::uint32_t n = r.u32("task count");
    const std::uint64_t hash = r.u64("structural hash");
    if (hashes != nullptr) (*hashes)[s] = hash;
    const std::size_t ms_at = r.pos();
    const double ms = r.f64("partition time");
    if (!std::isfinite(ms) || ms < 0) r.fail(ms_at, where + "expected a partition time >= 0");
    a.partition_ms[s] = ms;
    const std::uint8_t has_order = r.u8("order flag");
    if (has_order > 1) r.fail(r.pos() - 1, where + "expected order flag 0 or 1");
    if (n > r.left() / 4)
      r.fail(r.pos(), where + "task count " + std::to_string(n) +
                          " exceeds the file: expected at most " + std::to_string(r.left() / 4) +
                          " tasks in the " + std::to_string(r.left()) + " bytes left");
    as.proc.resize(n);
    for (std::uint32_t t = 0; t < n; ++t) {
      const std::size_t at = r.pos();
      as.proc[t] = r.u32("processor");
      if (as.proc[t] >= a.k)
        r.fail(at, where + "task " + std::to_string(t) + " on processor " +
                       std::to_string(as.proc[t]) + ", expected < k = " + std::to_string(a.k));
    }
    if (has_order == 0) continue;
    if (a.k > r.left() / 4)
      r.fail(r.pos(), where + "truncated: expected " + std::to_string(a.k) + " order lists");
    as.order.resize(a.k);
    std::vector<bool> seen(n, false);
    std::size_t listed = 0;
    for (std::uint32_t p = 0; p < a.k; ++p) {
      const std::uint32_t count = r.u32("order length");
      if (count > n - listed)
        r.fail(r.pos() - 4, where + "order of processor " + std::to_string(p) +
                                " too long: expected at most " + std::to_string(n - listed) +
                                " tasks, found " + std::to_string(count));
      as.order[p].resize(count);
      for (std::uint32_t i = 0; i < count; ++i) {
        const std::size_t at = r.pos();
        const TaskId t = r.u32("ordered task");
        if (t >= n || seen[t] || as.proc[t] != p)
          r.fail(at, where + "order of processor " + std::to_string(p) + " lists task " +
                         std::to_string(t) + ", expected an unlisted task of that processor");
        seen[t] = true;
        as.order[p][i] = t;
      }
      listed += count;
    }
    if (listed != n)
      r.fail(r.pos(), where + "expected the orders to list all " + std::to_string(n) +
                          " tasks, they list " + std::to_string(listed));
  }
  if (r.left() != 0)
    r.fail(r.pos(), "expected the checksum, found " + std::to_string(r.left()) + " more bytes");
  return a;
}

void write_assignment(const std::string& path, const TraceAssignment& a,
                      const std::vector<std::uint64_t>& hashes) {
  const std::vector<std::uint8_t> b = encode_assignment(a, hashes);
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(b.data()), b.size()));
}

TraceAssignment read_assignment(const std::string& path, std::vector<std::uint64_t>* hashes) {
  const std::vector<std::uint8_t> b = read_file_bytes(path);
  return decode_assignment(b, path, hashes);
}

void write_assignment(const std::string& path, const TraceAssignment& a, const Trace& trace) {
  std::vector<std::uint64_t> hashes;
  hashes.reserve(trace.steps.size());
  for (const StepGraph& g : trace.steps) hashes.push_back(g.structural_hash());
  write_assignment(path, a, hashes);
}

TraceAssignment load_assignment(const std::string& path, const Trace& trace,
                                const std::string& trace_name) {
  std::vector<std::uint64_t> hashes;
  TraceAssignment a = read_assignment(path, &hashes);
  check_fits(trace, a, path);
  for (std::size_t s = 0; s < hashes.size() && s < trace.steps.size(); ++s)
    if (hashes[s] != 0 && hashes[s] != trace.steps[s].structural_hash())
      throw InputError(path, std::nullopt,
                       "step " + std::to_string(s) +
                           " was partitioned for a graph of another structure than " + trace_name +
                           "'s");
  return a;
}

std::optional<TraceAssignment> load_assignment_if(const std::string& path, const Trace& trace,
                                                  const std::string& trace_name) {
  if (path.empty()) return std::nullopt;
  return load_assignment(path, trace, trace_name);
}

TraceAssignment load_or_partition(const Trace& trace, const std::string& trace_name,
                                  const std::string& path, const std::string& method,
                                  std::uint32_t k, PartitionNotes* notes) {
  if (k == 0) throw OptionError("threads", "must be at least 1");
  if (path.empty()) {
    const std::string m = method.empty() ? default_method(trace) : method;
    TracePartition p = partition_trace(trace, m, k, Options{});
    if (notes != nullptr) *notes = {m, std::move(p.placed_by), std::move(p.warnings)};
    return std::move(p.assignment);
  }
  TraceAssignment a = load_assignment(path, trace, trace_name);
  if (a.k != k)
    throw OptionError("threads", std::to_string(k) + " does not fit " + path +
                                     ": assignment has k = " + std::to_string(a.k));
  return a;
}

std::string assignment_label(const std::string& path, const std::string& method,
                             const PartitionNotes& notes) {
  if (!path.empty()) return path;
  std::string label = notes.placed_by + " (computed";
  if (method.empty())
    label += notes.method == "owner" ? ", default" : ", default for a trace without objects";
  if (notes.placed_by != notes.method) label += ", fallback of " + notes.method;
  return label + ")";
}

}  // namespace tgraph::partition
