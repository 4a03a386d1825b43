// SPDX-License-Identifier: MIT
// Reading the .tgt trace format (docs/trace-format.md): every count, id and length checked
// against the bytes left and the graph read so far; errors name the file and offset.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string_view>

#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "trace_format.hpp"

namespace tgraph {

using namespace detail;  // the format's constants

namespace {

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
    // ReadOptions::recover reads them: the command line says its flag.
    throw InputError(name_, pos,
                     kind + (detail.empty() ? "" : ": " + detail) + " (" +
                         steps_text(trace_.steps.size()) +
                         "; capture interrupted?) — read with {recover}",
                     kNamesFields);
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
    const StepGraph& src = trace_.steps[ref];
    StepGraph g = structure_of(src);
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

  // The u32 id `field` read from `p`, checked against `n` (object ids: kNoObject allowed).
  std::uint32_t read_id(ByteReader& p, const char* field, std::size_t n, const char* what) const {
    const std::size_t at = p.pos();
    const std::uint32_t id = p.u32(field);
    check_id(at, id, n, what);
    return id;
  }
  std::uint32_t read_object(ByteReader& p, const char* field, std::size_t n,
                            const char* what) const {
    const std::size_t at = p.pos();
    const std::uint32_t id = p.u32(field);
    check_object(at, id, n, what);
    return id;
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
      d.object = read_object(p, "u32 datum object", n_objects, "datum");
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
      t.kind = read_id(p, "u32 task kind", n_kinds, "task kind id");
      t.object = read_object(p, "u32 task object", n_objects, "task");
      const std::size_t at = p.pos();
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
      loop.condition = read_id(p, "u32 loop condition", n_data, "loop condition datum id");
      const std::size_t at = p.pos();
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
      c.a = read_id(p, "u32 contact object a", g.objects.size(), "contact object id");
      c.b = read_id(p, "u32 contact object b", g.objects.size(), "contact object id");
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

}  // namespace

Trace read_trace_bytes(std::span<const std::uint8_t> bytes, const std::string& name,
                       const ReadOptions& options) {
  return TraceDecoder(bytes, name, options).decode();
}

Trace read_trace(const std::string& path, const ReadOptions& options) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return read_trace_bytes(bytes, path, options);
}

}  // namespace tgraph
