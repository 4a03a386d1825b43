// SPDX-License-Identifier: MIT
// Writing the .tgt trace format: little-endian frames with CRC-32, structure dedupe
// (docs/trace-format.md); TraceWriter streams steps to a partial file renamed on close().
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>

#include "fd_write.hpp"
#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "trace_format.hpp"

namespace tgraph {

using namespace detail;  // the format's constants

namespace {

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

// A list of the format: its length as u32 (UsageError naming `what` if it does not fit),
// then each element as `element` writes it.
template <class List, class Element>
void encode_list(ByteWriter& w, const List& list, const char* what, Element element) {
  w.count(list.size(), what);
  for (const auto& e : list) element(e);
}

void encode_structure(ByteWriter& w, const StepGraph& g) {
  encode_list(w, g.kinds, "kinds", [&](const std::string& k) { w.str(k); });
  encode_list(w, g.objects, "objects", [&](const ObjectInfo& o) { w.str(o.name); });
  encode_list(w, g.data, "data", [&](const Datum& d) {
    w.str(d.name);
    w.u32(d.object);
    w.u64(d.bytes);
  });
  encode_list(w, g.accesses, "accesses", [&](const Access& a) {
    w.u32(a.datum);
    w.u8(static_cast<std::uint8_t>(a.mode));
  });
  encode_list(w, g.tasks, "tasks", [&](const Task& t) {
    w.u32(t.kind);
    w.u32(t.object);
    w.u32(t.access_count);  // access_begin is the running sum (validate() requires it)
    w.u32(t.loop);
    w.u64(t.key);
  });
  encode_list(w, g.loops, "loops", [&](const Loop& l) {
    w.u32(l.condition);
    w.u32(l.first);
    w.u32(l.last);
    w.u32(l.max_iterations);
  });
}

void encode_step_values(ByteWriter& w, const StepGraph& g) {
  encode_list(w, g.tasks, "tasks", [&](const Task& t) { w.u64(t.cost_ns); });
  encode_list(w, g.loops, "loops", [&](const Loop& l) { w.u32(l.iterations); });
  encode_list(w, g.contacts, "contacts", [&](const Contact& c) {
    w.u32(c.a);
    w.u32(c.b);
  });
  encode_list(w, g.groups, "groups", [&](std::uint32_t group) { w.u32(group); });
  w.u64(g.host_ns);
}

}  // namespace

// Named (not file-local): TraceWriter::Impl holds one, and a type of the anonymous namespace
// in a member is a warning (-Wsubobject-linkage) where this file is part of a unity batch.
namespace detail {

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
    by_hash_[hash].push_back(shapes_.size());
    shapes_.push_back(structure_of(step));
    shape_step_.push_back(steps_);
  }

  std::unordered_map<std::uint64_t, std::vector<std::size_t>> by_hash_;
  std::vector<StepGraph> shapes_;
  std::vector<std::uint32_t> shape_step_;  // step index of each shape's full frame
  std::uint32_t steps_ = 0;
  bool reuse_structure_ = true;
};

}  // namespace detail

namespace {

void encode_end(std::vector<std::uint8_t>& out, std::uint32_t steps) {
  const std::size_t at = begin_frame(out);
  ByteWriter(out).u32(steps);
  finish_frame(out, at, FrameType::End);
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
      detail::write_all(
          fd, std::string_view(reinterpret_cast<const char*>(buffer.data()), buffer.size()),
          partial);
    } catch (...) {
      if (::ftruncate(fd, static_cast<::off_t>(written)) != 0) {
        // Nothing more to do: the reader with ReadOptions::recover skips a partial last frame.
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

// The header frame is written before the partial file gets its name where the file system
// allows it (an unnamed O_TMPFILE file, then linked): a process killed at any moment leaves
// either no partial file or one that starts with a whole header (an empty one otherwise,
// killed between its creation and the first write).
TraceWriter::TraceWriter(const std::string& path, const TraceHeader& header)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->partial = path + ".partial";
  encode_file_header(impl_->buffer, header);
  impl_->fd = detail::open_unnamed_beside(impl_->partial);
  if (impl_->fd >= 0) {
    impl_->flush_buffer();
    if (detail::name_unnamed(impl_->fd, impl_->partial)) return;
    ::close(impl_->fd);
    impl_->written = 0;
    encode_file_header(impl_->buffer, header);  // flush_buffer() emptied it
  }
  impl_->fd = ::open(impl_->partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (impl_->fd < 0) throw Error(impl_->partial + ": cannot create: " + std::strerror(errno));
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
  detail::sync_close_rename(fd, impl_->partial, impl_->path, impl_->partial, impl_->partial);
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

}  // namespace tgraph
