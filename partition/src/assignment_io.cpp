// SPDX-License-Identifier: MIT
// The .tga file: see docs/assignment-format.md.
#include "tgraph/partition/assignment_io.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string_view>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/partition/evaluate.hpp"

namespace tgraph::partition {

namespace {

static_assert(std::endian::native == std::endian::little,
              ".tga encoding assumes a little-endian host");

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'G', 'A', 'S'};
constexpr std::size_t kHeaderBytes = 4 + 4 + 8;           // magic, version, total length
constexpr std::size_t kMinBytes = kHeaderBytes + 12 + 4;  // + k, steps, method length; crc
constexpr std::uint32_t kMaxMethod = 256;
constexpr std::uint32_t kMaxK = 1u << 20;
constexpr std::size_t kStepHeader = 4 + 8 + 8 + 1;  // tasks, hash, partition ms, has order

std::uint32_t crc32(const std::uint8_t* p, std::size_t n) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int b = 0; b < 8; ++b) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

class Writer {
 public:
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u32(std::uint32_t v) { put(&v, 4); }
  void u64(std::uint64_t v) { put(&v, 8); }
  void f64(double v) { put(&v, 8); }
  void bytes(std::string_view s) { put(s.data(), s.size()); }
  std::vector<std::uint8_t>& out() { return out_; }

 private:
  void put(const void* p, std::size_t n) {
    const std::size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, p, n);
  }
  std::vector<std::uint8_t> out_;
};

class Reader {
 public:
  Reader(std::span<const std::uint8_t> b, std::size_t end, const std::string& name)
      : b_(b), end_(end), name_(name) {}
  std::size_t offset() const { return pos_; }
  std::size_t left() const { return end_ - pos_; }
  [[noreturn]] void fail(const std::string& what) const { fail_at(pos_, what); }
  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    throw InputError(name_, at, what);
  }
  void need(std::size_t n, const char* what) const {
    if (left() < n) fail(std::string("truncated: expected ") + what);
  }
  std::uint8_t u8(const char* what) {
    need(1, what);
    return b_[pos_++];
  }
  std::uint32_t u32(const char* what) {
    std::uint32_t v;
    get(&v, 4, what);
    return v;
  }
  std::uint64_t u64(const char* what) {
    std::uint64_t v;
    get(&v, 8, what);
    return v;
  }
  double f64(const char* what) {
    double v;
    get(&v, 8, what);
    return v;
  }
  std::string str(std::size_t n, const char* what) {
    need(n, what);
    std::string s(reinterpret_cast<const char*>(b_.data() + pos_), n);
    pos_ += n;
    return s;
  }

 private:
  void get(void* p, std::size_t n, const char* what) {
    need(n, what);
    std::memcpy(p, b_.data() + pos_, n);
    pos_ += n;
  }
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
  std::size_t end_;
  const std::string& name_;
};

}  // namespace

std::vector<std::uint8_t> encode_assignment(const TraceAssignment& a,
                                            const std::vector<std::uint64_t>& hashes) {
  Writer w;
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
  std::vector<std::uint8_t>& out = w.out();
  const std::uint64_t total = out.size() + 4;
  std::memcpy(out.data() + 8, &total, 8);
  const std::uint32_t crc = crc32(out.data(), out.size());
  w.u32(crc);
  return std::move(out);
}

TraceAssignment decode_assignment(std::span<const std::uint8_t> bytes, const std::string& name,
                                  std::vector<std::uint64_t>* hashes) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic.data(), 4) != 0)
    throw InputError(name, 0, "expected magic \"TGAS\" (not a .tga assignment file)");
  if (bytes.size() < kMinBytes)
    throw InputError(
        name, bytes.size(),
        "truncated: expected a header of at least " + std::to_string(kMinBytes) + " bytes");
  Reader head(bytes, bytes.size(), name);
  head.u32("magic");
  const std::uint32_t version = head.u32("version");
  if (version != kAssignmentVersion)
    head.fail_at(4, "unsupported version " + std::to_string(version) + " (expected " +
                        std::to_string(kAssignmentVersion) + ")");
  const std::uint64_t total = head.u64("total length");
  if (total > bytes.size())
    throw InputError(name, bytes.size(),
                     "truncated: header says " + std::to_string(total) + " bytes, file has " +
                         std::to_string(bytes.size()));
  if (total < bytes.size())
    throw InputError(name, total, "expected end of file after " + std::to_string(total) + " bytes");
  std::uint32_t stored_crc;
  std::memcpy(&stored_crc, bytes.data() + bytes.size() - 4, 4);
  if (crc32(bytes.data(), bytes.size() - 4) != stored_crc)
    throw InputError(name, bytes.size() - 4, "checksum mismatch (file corrupted)");

  Reader r(bytes, bytes.size() - 4, name);
  r.str(kHeaderBytes, "header");
  TraceAssignment a;
  const std::size_t k_at = r.offset();
  a.k = r.u32("k");
  if (a.k == 0 || a.k > kMaxK)
    r.fail_at(k_at, "expected k in [1, " + std::to_string(kMaxK) + "], got " + std::to_string(a.k));
  const std::uint32_t steps = r.u32("step count");
  const std::uint32_t method_len = r.u32("method length");
  if (method_len > kMaxMethod)
    r.fail("method name longer than " + std::to_string(kMaxMethod) + " bytes");
  a.method = r.str(method_len, "method name");
  if (steps > r.left() / kStepHeader)
    r.fail("step count " + std::to_string(steps) + " exceeds the file");
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
    const std::size_t ms_at = r.offset();
    const double ms = r.f64("partition time");
    if (!std::isfinite(ms) || ms < 0) r.fail_at(ms_at, where + "expected a partition time >= 0");
    a.partition_ms[s] = ms;
    const std::uint8_t has_order = r.u8("order flag");
    if (has_order > 1) r.fail_at(r.offset() - 1, where + "expected order flag 0 or 1");
    if (n > r.left() / 4) r.fail(where + "task count " + std::to_string(n) + " exceeds the file");
    as.proc.resize(n);
    for (std::uint32_t t = 0; t < n; ++t) {
      const std::size_t at = r.offset();
      as.proc[t] = r.u32("processor");
      if (as.proc[t] >= a.k)
        r.fail_at(at, where + "task " + std::to_string(t) + " on processor " +
                          std::to_string(as.proc[t]) + ", expected < k = " + std::to_string(a.k));
    }
    if (has_order == 0) continue;
    if (a.k > r.left() / 4)
      r.fail(where + "truncated: expected " + std::to_string(a.k) + " order lists");
    as.order.resize(a.k);
    std::vector<bool> seen(n, false);
    std::size_t listed = 0;
    for (std::uint32_t p = 0; p < a.k; ++p) {
      const std::uint32_t count = r.u32("order length");
      if (count > n - listed)
        r.fail(where + "order of processor " + std::to_string(p) + " too long");
      as.order[p].resize(count);
      for (std::uint32_t i = 0; i < count; ++i) {
        const std::size_t at = r.offset();
        const TaskId t = r.u32("ordered task");
        if (t >= n || seen[t] || as.proc[t] != p)
          r.fail_at(at, where + "order of processor " + std::to_string(p) + " lists task " +
                            std::to_string(t) + ", expected an unlisted task of that processor");
        seen[t] = true;
        as.order[p][i] = t;
      }
      listed += count;
    }
    if (listed != n)
      r.fail(where + "order lists " + std::to_string(listed) + " of " + std::to_string(n) +
             " tasks");
  }
  if (r.left() != 0)
    r.fail("expected the checksum, found " + std::to_string(r.left()) + " more bytes");
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

}  // namespace tgraph::partition
