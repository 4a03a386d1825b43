// SPDX-License-Identifier: MIT
// The .tgt trace format: little-endian frames with CRC-32, structure dedupe (docs/trace-format.md).
#include "tgraph/graph/trace_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string_view>
#include <unordered_map>

#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph {

namespace {

constexpr std::array<std::uint8_t, 4> kMagic = {'T', 'G', 'T', 'R'};
constexpr std::uint32_t kFormatVersion = 2;
// Version 1 lacks the step's host time (StepGraph::host_ns, read as 0); still read.
constexpr std::uint32_t kOldestFormatVersion = 1;
constexpr std::size_t kFileHeaderSize = 8;    // magic + u32 version
constexpr std::size_t kFrameHeaderSize = 12;  // u32 type + u32 length + u32 crc

enum class FrameType : std::uint32_t { Header = 1, FullStep = 2, ReferenceStep = 3, End = 4 };

// Smallest encoded size of one element of each counted list: what `count * size <= bytes
// left` checks before anything is allocated.
constexpr std::uint64_t kStringMin = 4;
constexpr std::uint64_t kDatumSize = 4 + 4 + 8;         // name length, object, bytes
constexpr std::uint64_t kAccessSize = 4 + 1;            // datum, mode
constexpr std::uint64_t kTaskSize = 4 + 4 + 4 + 4 + 8;  // kind, object, access count, loop, key
constexpr std::uint64_t kLoopSize = 4 + 4 + 4 + 4;      // condition, first, last, max
constexpr std::uint64_t kCostSize = 8;
constexpr std::uint64_t kIterationSize = 4;
constexpr std::uint64_t kContactSize = 8;
constexpr std::uint64_t kGroupSize = 4;

// Decoded traces may be larger than the file (a reference frame repeats a whole structure):
// they are capped at kDecodedBase + kDecodedPerByte * file size bytes of memory.
constexpr std::uint64_t kDecodedBase = std::uint64_t{64} << 20;
constexpr std::uint64_t kDecodedPerByte = 128;

// ---------------------------------------------------------------------------------------
// Encoding

// Reserves a frame header at the end of `out`; finish_frame() fills it once the payload
// has been appended.
std::size_t begin_frame(std::vector<std::uint8_t>& out) {
  const std::size_t at = out.size();
  out.resize(at + kFrameHeaderSize);
  return at;
}

void finish_frame(std::vector<std::uint8_t>& out, std::size_t at, FrameType type) {
  const std::size_t length = out.size() - at - kFrameHeaderSize;
  if (length > std::numeric_limits<std::uint32_t>::max())
    throw UsageError("cannot write trace: a step encodes to more than 4 GiB");
  ByteWriter w(out);
  w.u32_at(at, static_cast<std::uint32_t>(type));
  w.u32_at(at + 4, static_cast<std::uint32_t>(length));
  // The checksum covers type, length and payload.
  const std::uint32_t crc = crc32(std::span(out).subspan(at + kFrameHeaderSize, length),
                                  crc32(std::span(out).subspan(at, 8)));
  w.u32_at(at + 8, crc);
}

void encode_file_header(std::vector<std::uint8_t>& out, const TraceHeader& header) {
  out.insert(out.end(), kMagic.begin(), kMagic.end());
  ByteWriter w(out);
  w.u32(kFormatVersion);
  const std::size_t at = begin_frame(out);
  w.str(header.scene);
  w.str(header.engine);
  w.str(header.machine);
  w.str(header.tgraph_version);
  finish_frame(out, at, FrameType::Header);
}

void encode_structure(ByteWriter& w, const StepGraph& g) {
  w.count(g.kinds.size(), "kinds");
  for (const auto& k : g.kinds) w.str(k);
  w.count(g.objects.size(), "objects");
  for (const auto& o : g.objects) w.str(o.name);
  w.count(g.data.size(), "data");
  for (const auto& d : g.data) {
    w.str(d.name);
    w.u32(d.object);
    w.u64(d.bytes);
  }
  w.count(g.accesses.size(), "accesses");
  for (const auto& a : g.accesses) {
    w.u32(a.datum);
    w.u8(static_cast<std::uint8_t>(a.mode));
  }
  w.count(g.tasks.size(), "tasks");
  for (const auto& t : g.tasks) {
    w.u32(t.kind);
    w.u32(t.object);
    w.u32(t.access_count);  // access_begin is the running sum (validate() requires it)
    w.u32(t.loop);
    w.u64(t.key);
  }
  w.count(g.loops.size(), "loops");
  for (const auto& l : g.loops) {
    w.u32(l.condition);
    w.u32(l.first);
    w.u32(l.last);
    w.u32(l.max_iterations);
  }
}

void encode_step_values(ByteWriter& w, const StepGraph& g) {
  w.count(g.tasks.size(), "tasks");
  for (const auto& t : g.tasks) w.u64(t.cost_ns);
  w.count(g.loops.size(), "loops");
  for (const auto& l : g.loops) w.u32(l.iterations);
  w.count(g.contacts.size(), "contacts");
  for (const auto& c : g.contacts) {
    w.u32(c.a);
    w.u32(c.b);
  }
  w.count(g.groups.size(), "groups");
  for (const auto g_id : g.groups) w.u32(g_id);
  w.u64(g.host_ns);
}

// Encodes steps one frame each, remembering structures already written so that a repeat
// becomes a reference frame. Candidates are found by structural_hash() and confirmed with
// same_structure(), which compares exactly the fields of the structure section.
class StepEncoder {
 public:
  explicit StepEncoder(bool reuse_structure = true) : reuse_structure_(reuse_structure) {}
  void encode(const StepGraph& step, std::vector<std::uint8_t>& out) {
    const std::string reason = step.validate();
    if (!reason.empty())
      throw UsageError("cannot write trace step " + std::to_string(steps_) + ": " + reason);
    if (steps_ == std::numeric_limits<std::uint32_t>::max())
      throw UsageError("cannot write trace: more than 2^32-1 steps");
    ByteWriter w(out);
    const std::size_t at = begin_frame(out);
    const std::uint64_t hash = step.structural_hash();
    const std::uint32_t earlier = reuse_structure_ ? find(hash, step) : kNone;
    if (earlier != kNone) {
      w.u32(earlier);
      encode_step_values(w, step);
      finish_frame(out, at, FrameType::ReferenceStep);
    } else {
      encode_structure(w, step);
      encode_step_values(w, step);
      finish_frame(out, at, FrameType::FullStep);
      if (reuse_structure_) remember(hash, step);
    }
    ++steps_;
  }
  std::uint32_t steps() const { return steps_; }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

  std::uint32_t find(std::uint64_t hash, const StepGraph& step) const {
    const auto it = by_hash_.find(hash);
    if (it == by_hash_.end()) return kNone;
    for (const std::size_t s : it->second)
      if (shapes_[s].same_structure(step)) return shape_step_[s];
    return kNone;
  }

  void remember(std::uint64_t hash, const StepGraph& step) {
    StepGraph shape;  // the structure only: what same_structure() compares
    shape.kinds = step.kinds;
    shape.objects = step.objects;
    shape.data = step.data;
    shape.tasks = step.tasks;
    shape.accesses = step.accesses;
    shape.loops = step.loops;
    by_hash_[hash].push_back(shapes_.size());
    shapes_.push_back(std::move(shape));
    shape_step_.push_back(steps_);
  }

  std::unordered_map<std::uint64_t, std::vector<std::size_t>> by_hash_;
  std::vector<StepGraph> shapes_;
  std::vector<std::uint32_t> shape_step_;  // step index of each shape's full frame
  std::uint32_t steps_ = 0;
  bool reuse_structure_ = true;
};

void encode_end(std::vector<std::uint8_t>& out, std::uint32_t steps) {
  const std::size_t at = begin_frame(out);
  ByteWriter(out).u32(steps);
  finish_frame(out, at, FrameType::End);
}

// ---------------------------------------------------------------------------------------
// Decoding

std::string hex_bytes(const std::uint8_t* p, std::size_t n) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    if (i) s += ' ';
    s += kHex[p[i] >> 4];
    s += kHex[p[i] & 15];
  }
  return s;
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

std::string steps_text(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " complete step" : " complete steps");
}

std::uint64_t string_memory(const std::string& s) {
  return sizeof(std::string) + (s.size() > 15 ? s.size() : 0);
}

// Memory held by the structure of a step (what a reference frame copies), edges included.
std::uint64_t structure_memory(const StepGraph& g) {
  std::uint64_t m = sizeof(StepGraph);
  for (const auto& k : g.kinds) m += string_memory(k);
  for (const auto& o : g.objects) m += string_memory(o.name);
  for (const auto& d : g.data) m += sizeof(Datum) - sizeof(std::string) + string_memory(d.name);
  m += g.tasks.size() * sizeof(Task) + g.accesses.size() * sizeof(Access) +
       g.loops.size() * sizeof(Loop) + (g.edges.size() + g.carried_edges.size()) * sizeof(Edge);
  return m;
}

class TraceDecoder {
 public:
  TraceDecoder(std::span<const std::uint8_t> bytes, const std::string& name,
               const ReadOptions& options)
      : bytes_(bytes), name_(name), options_(options) {
    const std::uint64_t size = bytes.size();
    budget_ = size > (std::numeric_limits<std::uint64_t>::max() - kDecodedBase) / kDecodedPerByte
                  ? std::numeric_limits<std::uint64_t>::max()
                  : kDecodedBase + kDecodedPerByte * size;
  }

  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const {
    throw InputError(name_, offset, what);
  }

  Trace decode() {
    read_file_header();
    std::size_t pos = kFileHeaderSize;
    for (;;) {
      const std::size_t left = bytes_.size() - pos;
      if (left == 0) {
        if (!have_header_)
          fail(pos, "expected a header frame after the file header, found the end of the file");
        return unclosed(pos, "trace not closed", "");
      }
      if (left < kFrameHeaderSize) {
        return unclosed(pos, "truncated frame header",
                        "expected " + std::to_string(kFrameHeaderSize) + " bytes, found " +
                            std::to_string(left));
      }
      const std::uint32_t type = get_u32(pos);
      const std::uint32_t length = get_u32(pos + 4);
      const std::uint32_t stored_crc = get_u32(pos + 8);
      if (type < static_cast<std::uint32_t>(FrameType::Header) ||
          type > static_cast<std::uint32_t>(FrameType::End)) {
        fail(pos, "unknown frame type " + std::to_string(type) +
                      ": expected 1 (header), 2 (full step), 3 (reference step) or 4 (end)");
      }
      if (length > left - kFrameHeaderSize) {
        return unclosed(pos, "truncated frame",
                        "expected " + std::to_string(length) + " payload bytes, found " +
                            std::to_string(left - kFrameHeaderSize));
      }
      const std::size_t begin = pos + kFrameHeaderSize;
      const std::size_t end = begin + length;
      const std::uint32_t crc = crc32(bytes_.subspan(begin, length), crc32(bytes_.subspan(pos, 8)));
      if (crc != stored_crc) {
        fail(pos, "checksum mismatch: expected CRC-32 " + hex32(stored_crc) +
                      " (stored in the frame), computed " + hex32(crc));
      }
      ByteReader p(bytes_, begin, end, name_, "the frame");
      const auto frame_type = static_cast<FrameType>(type);
      if (!have_header_ && frame_type != FrameType::Header)
        fail(pos,
             "expected the header frame (type 1) first, found frame type " + std::to_string(type));
      switch (frame_type) {
        case FrameType::Header:
          if (have_header_) fail(pos, "expected a step or end frame, found a second header frame");
          read_header(p);
          have_header_ = true;
          break;
        case FrameType::FullStep:
          read_full_step(p, pos);
          break;
        case FrameType::ReferenceStep:
          read_reference_step(p, pos);
          break;
        case FrameType::End: {
          const std::uint32_t n = p.u32("u32 step count of the end frame");
          p.expect_end("the frame payload");
          if (n != trace_.steps.size())
            fail(pos, "end frame count mismatch: expected " + std::to_string(trace_.steps.size()) +
                          " steps (frames read), the end frame says " + std::to_string(n));
          if (end != bytes_.size())
            fail(end, "expected the end of the file after the end frame, found " +
                          std::to_string(bytes_.size() - end) + " more bytes");
          return std::move(trace_);
        }
      }
      pos = end;
    }
  }

 private:
  std::uint32_t get_u32(std::size_t at) const {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
      v |= std::uint32_t{bytes_[at + static_cast<std::size_t>(i)]} << (8 * i);
    return v;
  }

  void read_file_header() {
    if (bytes_.size() < kFileHeaderSize) {
      fail(0, "truncated file header: expected " + std::to_string(kFileHeaderSize) +
                  " bytes (magic \"TGTR\", u32 format version), found " +
                  std::to_string(bytes_.size()) + (bytes_.empty() ? " (empty file)" : ""));
    }
    if (!std::equal(kMagic.begin(), kMagic.end(), bytes_.begin()))
      fail(0, "bad magic: expected \"TGTR\" (" + hex_bytes(kMagic.data(), 4) + "), found " +
                  hex_bytes(bytes_.data(), 4) + " (not a .tgt trace)");
    const std::uint32_t version = get_u32(4);
    if (version < kOldestFormatVersion || version > kFormatVersion)
      fail(4, "unsupported format version " + std::to_string(version) + ": expected " +
                  std::to_string(kOldestFormatVersion) + " to " + std::to_string(kFormatVersion));
    version_ = version;
  }

  // The data end cleanly or in a partial frame, without an end frame.
  // `kind` names the problem, `detail` says what was expected (may be empty).
  Trace unclosed(std::size_t pos, const std::string& kind, const std::string& detail) {
    if (!have_header_) fail(pos, "truncated header frame: " + detail);
    if (options_.recover) return std::move(trace_);
    fail(pos, kind + (detail.empty() ? "" : ": " + detail) + " (" +
                  steps_text(trace_.steps.size()) +
                  "; capture interrupted?) — read with --recover");
  }

  void read_header(ByteReader& p) {
    trace_.header.scene = p.str("scene string");
    trace_.header.engine = p.str("engine string");
    trace_.header.machine = p.str("machine string");
    trace_.header.tgraph_version = p.str("tgraph version string");
    p.expect_end("the frame payload");
  }

  void read_full_step(ByteReader& p, std::size_t frame) {
    check_step_count(frame);
    StepGraph g;
    read_structure(p, g);
    read_step_values(p, g);
    p.expect_end("the frame payload");
    check_valid(g, frame);
    const std::uint64_t left = budget_ > decoded_ ? budget_ - decoded_ : 0;
    if (!g.derive_edges(static_cast<std::size_t>(left / sizeof(Edge))))
      fail(frame, "step " + std::to_string(trace_.steps.size()) +
                      " has more dependencies than the memory bound allows: expected at most " +
                      std::to_string(left / sizeof(Edge)) + " edges");
    charge(structure_memory(g) + values_memory(g), frame);
    shape_memory_.push_back(structure_memory(g));
    trace_.steps.push_back(std::move(g));
  }

  void read_reference_step(ByteReader& p, std::size_t frame) {
    check_step_count(frame);
    const std::size_t ref_at = p.pos();
    const std::uint32_t ref = p.u32("u32 referenced step index");
    if (ref >= trace_.steps.size())
      fail(ref_at, "reference to a non-existent step: expected an earlier step index < " +
                       std::to_string(trace_.steps.size()) + ", found " + std::to_string(ref));
    // Checked before copying: a small frame may repeat a large structure.
    charge(shape_memory_[ref], frame);
    StepGraph g;
    const StepGraph& src = trace_.steps[ref];
    g.kinds = src.kinds;
    g.objects = src.objects;
    g.data = src.data;
    g.tasks = src.tasks;
    g.accesses = src.accesses;
    g.loops = src.loops;
    // Edges depend on the structure only: copied, not derived again.
    g.edges = src.edges;
    g.carried_edges = src.carried_edges;
    read_step_values(p, g);
    p.expect_end("the frame payload");
    check_valid(g, frame);
    charge(values_memory(g), frame);
    shape_memory_.push_back(shape_memory_[ref]);
    trace_.steps.push_back(std::move(g));
  }

  void check_step_count(std::size_t frame) const {
    if (trace_.steps.size() >= std::numeric_limits<std::uint32_t>::max())
      fail(frame, "expected at most 2^32-1 steps");
  }

  void check_valid(const StepGraph& g, std::size_t frame) const {
    const std::string reason = g.validate();
    if (!reason.empty())
      fail(frame, "invalid step " + std::to_string(trace_.steps.size()) + ": " + reason);
  }

  static std::uint64_t values_memory(const StepGraph& g) {
    return g.contacts.size() * sizeof(Contact) + g.groups.size() * sizeof(std::uint32_t);
  }

  void charge(std::uint64_t bytes, std::size_t frame) {
    decoded_ += bytes;
    if (decoded_ > budget_)
      fail(frame, "decoded trace too large: expected at most " + std::to_string(budget_) +
                      " bytes of memory (64 MiB + 128 x file size), step " +
                      std::to_string(trace_.steps.size()) + " brings it to " +
                      std::to_string(decoded_));
  }

  // Object ids may also be kNoObject.
  void check_object(std::size_t at, std::uint32_t id, std::size_t n, const char* what) const {
    if (id != kNoObject && id >= n)
      fail(at, std::string("id out of range: expected ") + what + " object id < " +
                   std::to_string(n) + " or 4294967295 (none), found " + std::to_string(id));
  }

  void check_id(std::size_t at, std::uint32_t id, std::size_t n, const char* what) const {
    if (id >= n)
      fail(at, std::string("id out of range: expected ") + what + " < " + std::to_string(n) +
                   ", found " + std::to_string(id));
  }

  void read_structure(ByteReader& p, StepGraph& g) {
    const std::uint32_t n_kinds = p.count("kinds", kStringMin);
    g.kinds.reserve(n_kinds);
    for (std::uint32_t i = 0; i < n_kinds; ++i) g.kinds.push_back(p.str("kind name"));

    const std::uint32_t n_objects = p.count("objects", kStringMin);
    g.objects.reserve(n_objects);
    for (std::uint32_t i = 0; i < n_objects; ++i) g.objects.push_back({p.str("object name")});

    const std::uint32_t n_data = p.count("data", kDatumSize);
    g.data.reserve(n_data);
    for (std::uint32_t i = 0; i < n_data; ++i) {
      Datum d;
      d.name = p.str("datum name");
      const std::size_t at = p.pos();
      d.object = p.u32("u32 datum object");
      check_object(at, d.object, n_objects, "datum");
      d.bytes = p.u64("u64 datum bytes");
      g.data.push_back(std::move(d));
    }

    const std::uint32_t n_accesses = p.count("accesses", kAccessSize);
    g.accesses.resize(n_accesses);
    for (auto& a : g.accesses) {
      const std::size_t at = p.pos();
      a.datum = p.u32("u32 access datum");
      check_id(at, a.datum, n_data, "access datum id");
      const std::uint8_t mode = p.u8("u8 access mode");
      if (mode > static_cast<std::uint8_t>(AccessMode::CW))
        fail(at + 4, "expected access mode 0..3 (R, W, RW, CW), found " + std::to_string(mode));
      a.mode = static_cast<AccessMode>(mode);
    }

    const std::uint32_t n_tasks = p.count("tasks", kTaskSize);
    g.tasks.resize(n_tasks);
    std::vector<std::size_t> loop_field_at(n_tasks);
    std::uint64_t next_access = 0;
    for (std::uint32_t i = 0; i < n_tasks; ++i) {
      Task& t = g.tasks[i];
      std::size_t at = p.pos();
      t.kind = p.u32("u32 task kind");
      check_id(at, t.kind, n_kinds, "task kind id");
      at = p.pos();
      t.object = p.u32("u32 task object");
      check_object(at, t.object, n_objects, "task");
      at = p.pos();
      t.access_count = p.u32("u32 task access count");
      if (t.access_count > n_accesses - next_access)
        fail(at, "id out of range: expected task " + std::to_string(i) + " to own at most the " +
                     std::to_string(n_accesses - next_access) +
                     " accesses left, found access count " + std::to_string(t.access_count));
      t.access_begin = static_cast<std::uint32_t>(next_access);
      next_access += t.access_count;
      loop_field_at[i] = p.pos();
      t.loop = p.u32("u32 task loop");
      t.key = p.u64("u64 task stable key");
    }
    if (next_access != n_accesses)
      fail(p.pos(), "expected the tasks' access counts to add up to the " +
                        std::to_string(n_accesses) + " accesses, they add up to " +
                        std::to_string(next_access));

    const std::uint32_t n_loops = p.count("loops", kLoopSize);
    g.loops.resize(n_loops);
    std::uint64_t prev_last = 0;
    for (std::uint32_t l = 0; l < n_loops; ++l) {
      Loop& loop = g.loops[l];
      std::size_t at = p.pos();
      loop.condition = p.u32("u32 loop condition");
      check_id(at, loop.condition, n_data, "loop condition datum id");
      at = p.pos();
      loop.first = p.u32("u32 loop first task");
      loop.last = p.u32("u32 loop last task");
      loop.max_iterations = p.u32("u32 loop max iterations");
      const std::string where = "malformed loop " + std::to_string(l) + ": expected ";
      if (loop.first >= loop.last || loop.last > n_tasks)
        fail(at, where + "first < last <= " + std::to_string(n_tasks) + " tasks, found [" +
                     std::to_string(loop.first) + ", " + std::to_string(loop.last) + ")");
      if (loop.first < prev_last)
        fail(at, where + "its body to start at or after task " + std::to_string(prev_last) +
                     " (loops sorted, not nested), found first task " + std::to_string(loop.first));
      prev_last = loop.last;
    }
    for (std::uint32_t i = 0; i < n_tasks; ++i) {
      const LoopId l = g.tasks[i].loop;
      if (l == kNoLoop) continue;
      check_id(loop_field_at[i], l, n_loops, "task loop id (or 4294967295 for none)");
      if (i < g.loops[l].first || i >= g.loops[l].last)
        fail(loop_field_at[i], "malformed loop " + std::to_string(l) + ": expected task " +
                                   std::to_string(i) + " marked with it to lie in its body [" +
                                   std::to_string(g.loops[l].first) + ", " +
                                   std::to_string(g.loops[l].last) + ")");
    }
    for (std::uint32_t l = 0; l < n_loops; ++l)
      for (TaskId t = g.loops[l].first; t < g.loops[l].last; ++t)
        if (g.tasks[t].loop != l)
          fail(loop_field_at[t], "malformed loop " + std::to_string(l) + ": expected task " +
                                     std::to_string(t) + " in its body to be marked with loop " +
                                     std::to_string(l));
  }

  void read_step_values(ByteReader& p, StepGraph& g) {
    std::size_t at = p.pos();
    const std::uint32_t n_costs = p.count("task costs", kCostSize);
    if (n_costs != g.tasks.size())
      fail(at, "expected " + std::to_string(g.tasks.size()) + " task costs (one per task), found " +
                   std::to_string(n_costs));
    for (auto& t : g.tasks) t.cost_ns = p.u64("u64 task cost");

    at = p.pos();
    const std::uint32_t n_iterations = p.count("loop iteration counts", kIterationSize);
    if (n_iterations != g.loops.size())
      fail(at, "expected " + std::to_string(g.loops.size()) +
                   " loop iteration counts (one per loop), found " + std::to_string(n_iterations));
    for (auto& l : g.loops) l.iterations = p.u32("u32 loop iterations");

    const std::uint32_t n_contacts = p.count("contacts", kContactSize);
    g.contacts.resize(n_contacts);
    for (auto& c : g.contacts) {
      at = p.pos();
      c.a = p.u32("u32 contact object a");
      check_id(at, c.a, g.objects.size(), "contact object id");
      at = p.pos();
      c.b = p.u32("u32 contact object b");
      check_id(at, c.b, g.objects.size(), "contact object id");
    }

    at = p.pos();
    const std::uint32_t n_groups = p.count("groups", kGroupSize);
    if (n_groups != 0 && n_groups != g.objects.size())
      fail(at, "expected 0 or " + std::to_string(g.objects.size()) +
                   " collision groups (one per object), found " + std::to_string(n_groups));
    g.groups.resize(n_groups);
    for (auto& group : g.groups) group = p.u32("u32 collision group");
    g.host_ns = version_ >= 2 ? p.u64("u64 host time") : 0;
  }

  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  ReadOptions options_;
  Trace trace_;
  bool have_header_ = false;
  std::vector<std::uint64_t> shape_memory_;  // structure_memory() of each step read
  std::uint64_t decoded_ = 0;
  std::uint64_t budget_ = 0;
  std::uint32_t version_ = kFormatVersion;  // of the file being read
};

// Writes all of `bytes` with write(2): one call unless the kernel writes less.
void write_all(int fd, const std::vector<std::uint8_t>& bytes, const std::string& path) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ::ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(path + ": cannot write: " + std::strerror(errno));
    }
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// TraceWriter

struct TraceWriter::Impl {
  std::string path;     // where close() puts the finished trace
  std::string partial;  // what is written until then
  int fd = -1;
  StepEncoder encoder;
  std::vector<std::uint8_t> buffer;  // reused frame buffer
  std::uint64_t written = 0;
  std::uint32_t steps = 0;  // step frames completely written

  std::string closed_because;  // why appends are refused once fd is closed

  // Writes the buffered frame. After a failed write (disk full, file size limit) the writer
  // cuts the file back to the end of the last complete frame, closes it and refuses further
  // frames, so the partial file holds exactly the frames written before.
  void flush_buffer() {
    try {
      write_all(fd, buffer, partial);
    } catch (...) {
      if (::ftruncate(fd, static_cast<::off_t>(written)) != 0) {
        // Nothing more to do: the reader with --recover skips a partial last frame.
      }
      ::close(fd);
      fd = -1;
      closed_because = "a failed write";
      throw;
    }
    written += buffer.size();
    buffer.clear();
  }
};

TraceWriter::TraceWriter(const std::string& path, const TraceHeader& header)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->partial = path + ".partial";
  impl_->fd = ::open(impl_->partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (impl_->fd < 0) throw Error(impl_->partial + ": cannot create: " + std::strerror(errno));
  encode_file_header(impl_->buffer, header);
  impl_->flush_buffer();
}

// Without close() no end frame is written and nothing is renamed: the partial file reads
// as an interrupted trace (with ReadOptions::recover).
TraceWriter::~TraceWriter() {
  if (impl_ && impl_->fd >= 0) ::close(impl_->fd);
}

void TraceWriter::append(const StepGraph& step) {
  if (impl_->fd < 0)
    throw UsageError(impl_->partial + ": append() after " + impl_->closed_because);
  impl_->buffer.clear();
  impl_->encoder.encode(step, impl_->buffer);
  impl_->flush_buffer();
  ++impl_->steps;
}

void TraceWriter::close() {
  if (impl_->fd < 0) return;
  impl_->buffer.clear();
  encode_end(impl_->buffer, impl_->encoder.steps());
  impl_->flush_buffer();
  const int fd = impl_->fd;
  impl_->fd = -1;
  impl_->closed_because = "close()";
  // The data reach the disk before the rename makes them the trace (as write_file_atomic).
  if (::fsync(fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(fd);
    throw Error(impl_->partial + ": cannot sync: " + std::strerror(err));
  }
  if (::close(fd) != 0) throw Error(impl_->partial + ": cannot close: " + std::strerror(errno));
  if (::rename(impl_->partial.c_str(), impl_->path.c_str()) != 0)
    throw Error(impl_->path + ": cannot rename " + impl_->partial + " into place: " +
                std::strerror(errno));
}

const std::string& TraceWriter::partial_path() const { return impl_->partial; }

// Not encoder.steps(): a step whose write failed was encoded but is not in the file.
std::uint32_t TraceWriter::steps_written() const { return impl_->steps; }

std::uint64_t TraceWriter::bytes_written() const { return impl_->written; }

// ---------------------------------------------------------------------------------------
// Whole traces

std::vector<std::uint8_t> encode_trace(const Trace& trace, const WriteOptions& options) {
  std::vector<std::uint8_t> out;
  encode_file_header(out, trace.header);
  StepEncoder encoder(options.reuse_structure);
  for (const StepGraph& step : trace.steps) encoder.encode(step, out);
  encode_end(out, encoder.steps());
  return out;
}

void write_trace(const std::string& path, const Trace& trace, const WriteOptions& options) {
  const std::vector<std::uint8_t> bytes = encode_trace(trace, options);
  write_file_atomic(path,
                    std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

Trace read_trace_bytes(std::span<const std::uint8_t> bytes, const std::string& name,
                       const ReadOptions& options) {
  return TraceDecoder(bytes, name, options).decode();
}

Trace read_trace(const std::string& path, const ReadOptions& options) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return read_trace_bytes(bytes, path, options);
}

}  // namespace tgraph
