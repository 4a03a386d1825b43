// SPDX-License-Identifier: MIT
// The .tgt format: round trips, structure dedupe, streaming, and every class of corruption.
#include "tgraph/graph/trace_io.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph {
namespace {

namespace fs = std::filesystem;
using M = AccessMode;
using Bytes = std::vector<std::uint8_t>;

// ---- building blocks -------------------------------------------------------------------

// A step with a dynamic loop, shared and owned data, contacts and groups. `variant`
// changes the structure; `salt` changes only costs, iterations, contacts and groups.
StepGraph make_step(int variant, int salt) {
  StepGraph g;
  const KindId integrate = g.intern_kind("integrate");
  const KindId dot = g.intern_kind("dot");
  const KindId brk = g.intern_kind("loop.break");
  const int n_objects = 3 + variant;
  for (int o = 0; o < n_objects; ++o) g.objects.push_back({"body" + std::to_string(o)});
  for (int o = 0; o < n_objects; ++o)
    g.data.push_back(
        {"x" + std::to_string(o), static_cast<ObjectId>(o), 24u * static_cast<unsigned>(o + 1)});
  const auto r = static_cast<DatumId>(g.data.size());
  g.data.push_back({"cg.r", kNoObject, 8});
  const auto done = static_cast<DatumId>(g.data.size());
  g.data.push_back({"cg.done", kNoObject, 1});
  auto cost = [&](int t) { return static_cast<std::uint64_t>(100 + 7 * t + 13 * salt); };
  for (int o = 0; o < n_objects; ++o) {
    std::vector<Access> acc{{static_cast<DatumId>(o), M::RW}};
    g.add_task(integrate, static_cast<ObjectId>(o), acc, cost(o), 1000u + static_cast<unsigned>(o));
  }
  // Loop body: one CW contribution per object, then the break reading the condition.
  Loop loop;
  loop.first = static_cast<TaskId>(g.tasks.size());
  for (int o = 0; o < n_objects; ++o) {
    std::vector<Access> acc{{static_cast<DatumId>(o), M::R}, {r, M::CW}};
    const TaskId t = g.add_task(dot, static_cast<ObjectId>(o), acc, cost(10 + o),
                                2000u + static_cast<unsigned>(o));
    g.tasks[t].loop = 0;
  }
  std::vector<Access> acc{{r, M::R}, {done, M::W}, {done, M::R}};
  const TaskId b = g.add_task(brk, kNoObject, acc, cost(99), 3000);
  g.tasks[b].loop = 0;
  loop.last = b + 1;
  loop.condition = done;
  loop.iterations = 1 + static_cast<std::uint32_t>(salt % 5);
  loop.max_iterations = 50;
  g.loops.push_back(loop);
  if (salt % 2 == 0) g.contacts.push_back({0, 1});
  if (salt % 3 == 0) g.contacts.push_back({1, 2});
  if (salt % 4 != 1)
    for (int o = 0; o < n_objects; ++o)
      g.groups.push_back(static_cast<std::uint32_t>((o + salt) % 2));
  return g;
}

Trace make_trace(const std::vector<int>& variants) {
  Trace t;
  t.header = {"bars64", "tgraph-engine", "2-core test VM", "0.1.0"};
  int salt = 0;
  for (int v : variants) t.steps.push_back(make_step(v, salt++));
  for (auto& s : t.steps) s.derive_edges();
  return t;
}

fs::path temp_path(const std::string& name) {
  return fs::path(::testing::TempDir()) / ("trace_io_test_" + name);
}

Bytes slurp(const fs::path& p) { return read_file_bytes(p.string()); }

// Message of the InputError that reading `bytes` raises ("" when it reads fine).
std::string read_error(const Bytes& bytes, bool recover = false) {
  ReadOptions o;
  o.recover = recover;
  try {
    read_trace_bytes(bytes, "t.tgt", o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Bitwise CRC-32 (independent of the table-driven one in the library).
std::uint32_t crc32_bitwise(const std::uint8_t* p, std::size_t n, std::uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// Little-endian byte builder for hand-made traces.
struct Buf {
  Bytes b;
  Buf& u8(std::uint8_t v) {
    b.push_back(v);
    return *this;
  }
  Buf& u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Buf& u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Buf& str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    b.insert(b.end(), s.begin(), s.end());
    return *this;
  }
  Buf& raw(const Bytes& more) {
    b.insert(b.end(), more.begin(), more.end());
    return *this;
  }
};

std::uint32_t get_u32(const Bytes& b, std::size_t at) {
  return std::uint32_t{b[at]} | std::uint32_t{b[at + 1]} << 8 | std::uint32_t{b[at + 2]} << 16 |
         std::uint32_t{b[at + 3]} << 24;
}

Bytes frame(std::uint32_t type, const Bytes& payload) {
  Buf head;
  head.u32(type).u32(static_cast<std::uint32_t>(payload.size()));
  std::uint32_t crc = crc32_bitwise(head.b.data(), 8);
  crc = crc32_bitwise(payload.data(), payload.size(), crc);
  head.u32(crc);
  return head.raw(payload).b;
}

constexpr std::uint32_t kVersion = 2;  // what the writer writes (docs/trace-format.md)

Bytes file_header(std::uint32_t version = kVersion) {
  return Buf().u8('T').u8('G').u8('T').u8('R').u32(version).b;
}

Bytes header_frame() {
  return frame(1, Buf().str("scene").str("engine").str("machine").str("0.1.0").b);
}

Bytes end_frame(std::uint32_t steps) { return frame(4, Buf().u32(steps).b); }

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

// The fields of one full-step frame, written as the format says; tests break one field.
struct RawStep {
  struct D {
    std::string name;
    std::uint32_t object;
    std::uint64_t bytes;
  };
  struct A {
    std::uint32_t datum;
    std::uint8_t mode;
  };
  struct T {
    std::uint32_t kind, object, access_count, loop;
    std::uint64_t key;
  };
  struct L {
    std::uint32_t condition, first, last, max_iterations;
  };
  std::vector<std::string> kinds{"integrate", "loop.break"};
  std::vector<std::string> objects{"a", "b"};
  std::vector<D> data{{"x", 0, 8}, {"done", kNone, 1}};
  std::vector<A> accesses{{0, 2}, {0, 0}, {1, 1}, {1, 0}};
  std::vector<T> tasks{{0, 0, 1, kNone, 11}, {1, 1, 3, 0, 12}};
  std::vector<L> loops{{1, 1, 2, 9}};
  std::vector<std::uint64_t> costs{40, 50};
  std::vector<std::uint32_t> iterations{3};
  std::vector<std::pair<std::uint32_t, std::uint32_t>> contacts{{0, 1}};
  std::vector<std::uint32_t> groups{0, 0};
  std::uint64_t host_ns = 77;

  Bytes structure() const {
    Buf w;
    w.u32(static_cast<std::uint32_t>(kinds.size()));
    for (const auto& k : kinds) w.str(k);
    w.u32(static_cast<std::uint32_t>(objects.size()));
    for (const auto& o : objects) w.str(o);
    w.u32(static_cast<std::uint32_t>(data.size()));
    for (const auto& d : data) w.str(d.name).u32(d.object).u64(d.bytes);
    w.u32(static_cast<std::uint32_t>(accesses.size()));
    for (const auto& a : accesses) w.u32(a.datum).u8(a.mode);
    w.u32(static_cast<std::uint32_t>(tasks.size()));
    for (const auto& t : tasks)
      w.u32(t.kind).u32(t.object).u32(t.access_count).u32(t.loop).u64(t.key);
    w.u32(static_cast<std::uint32_t>(loops.size()));
    for (const auto& l : loops) w.u32(l.condition).u32(l.first).u32(l.last).u32(l.max_iterations);
    return w.b;
  }
  Bytes values() const {
    Buf w;
    w.u32(static_cast<std::uint32_t>(costs.size()));
    for (auto c : costs) w.u64(c);
    w.u32(static_cast<std::uint32_t>(iterations.size()));
    for (auto i : iterations) w.u32(i);
    w.u32(static_cast<std::uint32_t>(contacts.size()));
    for (auto [a, b] : contacts) w.u32(a).u32(b);
    w.u32(static_cast<std::uint32_t>(groups.size()));
    for (auto g : groups) w.u32(g);
    w.u64(host_ns);
    return w.b;
  }
  Bytes full_frame() const { return frame(2, Buf().raw(structure()).raw(values()).b); }
  Bytes reference_frame(std::uint32_t ref) const {
    return frame(3, Buf().u32(ref).raw(values()).b);
  }
};

// A complete trace of the given step frames.
Bytes trace_of(const std::vector<Bytes>& step_frames, std::uint32_t end_count) {
  Buf t;
  t.raw(file_header()).raw(header_frame());
  for (const auto& f : step_frames) t.raw(f);
  return t.raw(end_frame(end_count)).b;
}

Bytes trace_of(const RawStep& s) { return trace_of({s.full_frame()}, 1); }

// Frame types of an encoded trace, walking the 12-byte frame headers.
std::vector<std::uint32_t> frame_types(const Bytes& b) {
  std::vector<std::uint32_t> types;
  for (std::size_t pos = 8; pos + 12 <= b.size(); pos += 12 + get_u32(b, pos + 4))
    types.push_back(get_u32(b, pos));
  return types;
}

// Sanitizers reserve huge address ranges: no address-space limit under them.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// Run in a forked child: caps the address space at what the process already maps plus
// 256 MiB, reads `bytes` and exits 0 only when the reader answered with `substring`
// (3 when it ran out of memory instead, 1 for any other outcome).
[[noreturn]] void read_with_memory_cap(const Bytes& bytes, const std::string& substring) {
  std::uint64_t pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const rlim_t cap = static_cast<rlim_t>(pages) * 4096 + (rlim_t{256} << 20);
  const rlimit limit{cap, cap};
  setrlimit(RLIMIT_AS, &limit);
  try {
    read_trace_bytes(bytes, "capped");
  } catch (const InputError& e) {
    std::_Exit(std::string(e.what()).find(substring) != std::string::npos ? 0 : 1);
  } catch (const std::bad_alloc&) {
    std::_Exit(3);
  }
  std::_Exit(1);
}

#define EXPECT_READ_ERROR(bytes, substring)                                    \
  do {                                                                         \
    const std::string msg_ = read_error(bytes);                                \
    EXPECT_NE(msg_.find(substring), std::string::npos) << "message: " << msg_; \
    EXPECT_EQ(msg_.find('\n'), std::string::npos) << msg_;                     \
  } while (0)

// ---- round trips ------------------------------------------------------------------------

TEST(TraceIo, RoundTripKeepsCostsLoopsContactsGroupsAndEdges) {
  const Trace trace = make_trace({0, 1, 0, 0, 1, 2, 0});
  ASSERT_FALSE(trace.steps[0].edges.empty());
  ASSERT_FALSE(trace.steps[0].carried_edges.empty());
  const fs::path p = temp_path("roundtrip.tgt");
  write_trace(p.string(), trace);
  const Trace back = read_trace(p.string());
  ASSERT_EQ(back.steps.size(), trace.steps.size());
  for (std::size_t i = 0; i < trace.steps.size(); ++i)
    EXPECT_EQ(back.steps[i], trace.steps[i]) << "step " << i;
  EXPECT_EQ(back.header, trace.header);
  EXPECT_EQ(back, trace);
  EXPECT_EQ(back.steps[3].loops[0].iterations, 4u);
  EXPECT_EQ(back.steps[3].tasks[0].cost_ns, 100u + 13u * 3u);
}

TEST(TraceIo, RoundTripOfEmptyTraceAndEmptyStep) {
  Trace trace;
  EXPECT_EQ(read_trace_bytes(encode_trace(trace), "empty"), trace);
  trace.header.scene = std::string("with\0nul", 8);
  trace.steps.emplace_back();  // no tasks at all
  trace.steps.emplace_back();
  const Bytes bytes = encode_trace(trace);
  EXPECT_EQ(read_trace_bytes(bytes, "empty-steps"), trace);
  EXPECT_EQ(frame_types(bytes), (std::vector<std::uint32_t>{1, 2, 3, 4}));
}

TEST(TraceIo, WriteTraceTraceWriterAndEncodeTraceGiveTheSameBytes) {
  const Trace trace = make_trace({0, 1, 0});
  const Bytes encoded = encode_trace(trace);
  const fs::path whole = temp_path("whole.tgt");
  write_trace(whole.string(), trace);
  EXPECT_EQ(slurp(whole), encoded);

  const fs::path streamed = temp_path("streamed.tgt");
  TraceWriter w(streamed.string(), trace.header);
  for (const auto& s : trace.steps) w.append(s);
  w.close();
  EXPECT_EQ(w.bytes_written(), encoded.size());
  EXPECT_EQ(slurp(streamed), encoded);
}

// Reads an unclosed trace with --recover: `header` and more than `at_least` steps, step i
// being make_step(i % 3, i) (what the writers in these tests append).
void expect_recovered_steps(const Bytes& bytes, const TraceHeader& header, std::size_t at_least) {
  ReadOptions recover;
  recover.recover = true;
  const Trace back = read_trace_bytes(bytes, "unclosed", recover);
  EXPECT_EQ(back.header, header);
  ASSERT_GT(back.steps.size(), at_least);
  for (std::size_t i = 0; i < back.steps.size(); ++i) {
    StepGraph expected = make_step(static_cast<int>(i % 3), static_cast<int>(i));
    expected.derive_edges();
    ASSERT_EQ(back.steps[i], expected) << "step " << i;
  }
}

TEST(TraceWriter, StoresRepeatedStructureAsReferenceFrames) {
  const Trace trace = make_trace({0, 1, 0, 0, 1, 2});
  const Bytes bytes = encode_trace(trace);
  // header, full A, full B, ref A, ref A, ref B, full C, end
  EXPECT_EQ(frame_types(bytes), (std::vector<std::uint32_t>{1, 2, 2, 3, 3, 3, 2, 4}));
  // Reference frames name the step holding the full structure.
  std::vector<std::uint32_t> refs;
  for (std::size_t pos = 8; pos + 12 <= bytes.size(); pos += 12 + get_u32(bytes, pos + 4))
    if (get_u32(bytes, pos) == 3) refs.push_back(get_u32(bytes, pos + 12));
  EXPECT_EQ(refs, (std::vector<std::uint32_t>{0, 0, 1}));
}

TEST(TraceWriter, DedupeMakesTheFileSmallerThanFullFrames) {
  std::vector<int> variants(40, 0);
  const Trace trace = make_trace(variants);
  const std::size_t deduped = encode_trace(trace).size();
  // Without dedupe every step would be a full frame as in a one-step trace.
  Trace none;
  none.header = trace.header;
  const std::size_t base = encode_trace(none).size();
  std::size_t full = base;
  for (const auto& s : trace.steps) {
    Trace one = none;
    one.steps.push_back(s);
    full += encode_trace(one).size() - base;
  }
  EXPECT_LT(deduped * 2, full) << "deduped " << deduped << " vs full frames " << full;
}

TEST(TraceWriter, WithoutStructureReuseWritesEveryStepAsAFullFrame) {
  const Trace trace = make_trace({0, 1, 0, 0, 1});
  const Bytes full = encode_trace(trace, {.reuse_structure = false});
  EXPECT_EQ(frame_types(full), (std::vector<std::uint32_t>{1, 2, 2, 2, 2, 2, 4}));
  // Each full frame is the frame of a one-step trace of that step.
  Trace none;
  none.header = trace.header;
  const std::size_t base = encode_trace(none).size();
  std::size_t expected = base;
  for (const auto& s : trace.steps) {
    Trace one = none;
    one.steps.push_back(s);
    expected += encode_trace(one).size() - base;
  }
  EXPECT_EQ(full.size(), expected);
  EXPECT_GT(full.size(), encode_trace(trace).size());
  EXPECT_EQ(read_trace_bytes(full, "full-frames"), trace);
  const fs::path p = temp_path("full-frames.tgt");
  write_trace(p.string(), trace, {.reuse_structure = false});
  EXPECT_EQ(slurp(p), full);
}

TEST(TraceWriter, CompleteFramesReadBackBeforeClose) {
  const Trace trace = make_trace({0, 1, 0});
  const fs::path p = temp_path("open.tgt");
  fs::remove(p);
  TraceWriter w(p.string(), trace.header);
  for (const auto& s : trace.steps) w.append(s);
  EXPECT_EQ(w.partial_path(), p.string() + ".partial");
  EXPECT_EQ(w.steps_written(), 3u);
  EXPECT_FALSE(fs::exists(p));  // only the partial file exists until close()
  const Bytes open_bytes = slurp(w.partial_path());
  EXPECT_EQ(open_bytes.size(), w.bytes_written());
  EXPECT_READ_ERROR(
      open_bytes,
      "trace not closed (3 complete steps; capture interrupted?) — read with recover");
  ReadOptions recover;
  recover.recover = true;
  EXPECT_EQ(read_trace(w.partial_path(), recover), trace);
  w.close();
  EXPECT_EQ(read_trace(p.string()), trace);
  EXPECT_FALSE(fs::exists(p.string() + ".partial"));
  EXPECT_THROW(w.append(trace.steps[0]), UsageError);
}

TEST(TraceWriter, CaptureKilledBySigkillLeavesItsCompleteStepsReadable) {
  const fs::path p = temp_path("killed.tgt");
  fs::remove(p);
  const TraceHeader header{"killed", "test", "here", "0.1.0"};
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the "capture": appends steps until killed
    TraceWriter w(p.string(), header);
    for (int i = 0; i < 1000000; ++i) w.append(make_step(i % 3, i));
    std::_Exit(0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  std::error_code ec;
  const fs::path partial = p.string() + ".partial";
  while ((!fs::exists(partial, ec) || fs::file_size(partial, ec) < 200000) &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  const Bytes bytes = slurp(p.string() + ".partial");
  EXPECT_FALSE(fs::exists(p));
  EXPECT_READ_ERROR(bytes, "capture interrupted?) — read with recover");
  expect_recovered_steps(bytes, header, 10);
}

TEST(TraceWriter, DestroyedWithoutCloseLeavesAnUnclosedTrace) {
  const Trace trace = make_trace({0});
  const fs::path p = temp_path("unclosed.tgt");
  fs::remove(p);
  {
    TraceWriter w(p.string(), trace.header);
    w.append(trace.steps[0]);
  }
  EXPECT_FALSE(fs::exists(p));
  EXPECT_READ_ERROR(slurp(p.string() + ".partial"), "trace not closed (1 complete step;");
}

TEST(TraceWriter, RejectsAnInvalidStep) {
  const fs::path p = temp_path("invalid.tgt");
  TraceWriter w(p.string(), {});
  StepGraph g = make_step(0, 0);
  g.tasks[1].kind = 99;
  EXPECT_THROW(w.append(g), UsageError);
  Trace t;
  t.steps.push_back(g);
  EXPECT_THROW(encode_trace(t), UsageError);
}

TEST(TraceWriter, ReportsAnUnwritablePath) {
  EXPECT_THROW(TraceWriter("/nonexistent-folder/x.tgt", {}), Error);
  EXPECT_THROW(write_trace("/nonexistent-folder/x.tgt", Trace{}), Error);
}

TEST(TraceWriter, ClosingReplacesAnExistingFileOnlyWithTheCompleteTrace) {
  const Trace old_trace = make_trace({0});
  const Trace new_trace = make_trace({1, 2});
  const fs::path p = temp_path("replace.tgt");
  write_trace(p.string(), old_trace);
  TraceWriter w(p.string(), new_trace.header);
  w.append(new_trace.steps[0]);
  EXPECT_EQ(read_trace(p.string()), old_trace);  // untouched while the new one streams
  w.append(new_trace.steps[1]);
  w.close();
  EXPECT_EQ(read_trace(p.string()), new_trace);
}

// A write that fails (here: the file size limit, as a full disk would) leaves the partial
// file cut back to its complete frames; the writer refuses further steps.
TEST(TraceWriter, AFailedWriteLeavesTheCompleteFramesReadable) {
  const fs::path p = temp_path("fsize.tgt");
  fs::remove(p);
  fs::remove(p.string() + ".partial");
  const TraceHeader header{"fsize", "test", "here", "0.1.0"};
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::signal(SIGXFSZ, SIG_IGN);  // write() then fails with EFBIG instead of killing
    rlimit limit{20000, 20000};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) std::_Exit(3);
    TraceWriter w(p.string(), header);
    try {
      for (int i = 0; i < 100000; ++i) w.append(make_step(i % 3, i));
      std::_Exit(4);  // never ran out of room
    } catch (const Error& e) {
      const std::string msg = e.what();
      if (msg.find(".partial: cannot write: File too large") == std::string::npos) std::_Exit(5);
    }
    try {
      w.append(make_step(0, 0));
      std::_Exit(6);
    } catch (const UsageError&) {
    }
    std::_Exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0);
  EXPECT_FALSE(fs::exists(p));
  const Bytes bytes = slurp(p.string() + ".partial");
  EXPECT_LE(bytes.size(), 20000u);
  // Cut back to a frame boundary: the reader sees a clean end without an end frame.
  EXPECT_READ_ERROR(bytes, "trace not closed (");
  expect_recovered_steps(bytes, header, 5);
}

// ---- hand-made files and the reference encoder in the test agree ------------------------

TEST(TraceReader, ReadsAHandMadeTrace) {
  RawStep s;
  const Trace t = read_trace_bytes(trace_of({s.full_frame(), s.reference_frame(0)}, 2), "hand");
  EXPECT_EQ(t.header.scene, "scene");
  EXPECT_EQ(t.header.tgraph_version, "0.1.0");
  ASSERT_EQ(t.steps.size(), 2u);
  const StepGraph& g = t.steps[1];
  EXPECT_EQ(g.kinds, (std::vector<std::string>{"integrate", "loop.break"}));
  EXPECT_EQ(g.data[1].object, kNoObject);
  EXPECT_EQ(g.tasks[1].access_begin, 1u);
  EXPECT_EQ(g.tasks[1].access_count, 3u);
  EXPECT_EQ(g.tasks[1].cost_ns, 50u);
  EXPECT_EQ(g.accesses[0].mode, M::RW);
  EXPECT_EQ(g.loops[0].iterations, 3u);
  EXPECT_EQ(g.loops[0].max_iterations, 9u);
  EXPECT_EQ(g.contacts, (std::vector<Contact>{{0, 1}}));
  EXPECT_EQ(g.edges, (std::vector<Edge>{{0, 1, 0, EdgeKind::RAW}}));
  EXPECT_EQ(t.steps[0], t.steps[1]);
}

TEST(TraceReader, EncoderOutputMatchesTheHandMadeBytes) {
  RawStep s;
  Trace t = read_trace_bytes(trace_of(s), "hand");
  EXPECT_EQ(encode_trace(t), trace_of(s));
}

TEST(TraceReader, ReadsVersion1FramesWithoutTheHostTime) {
  RawStep s;
  const Trace v2 = read_trace_bytes(trace_of(s), "hand");
  ASSERT_EQ(v2.steps.size(), 1u);
  EXPECT_EQ(v2.steps[0].host_ns, 77u);
  // The same step as version 1 wrote it: no host time after the groups.
  Bytes payload = Buf().raw(s.structure()).raw(s.values()).b;
  payload.resize(payload.size() - 8);
  const Bytes v1_bytes =
      Buf().raw(file_header(1)).raw(header_frame()).raw(frame(2, payload)).raw(end_frame(1)).b;
  const Trace v1 = read_trace_bytes(v1_bytes, "hand-v1");
  ASSERT_EQ(v1.steps.size(), 1u);
  EXPECT_EQ(v1.steps[0].host_ns, 0u);
  StepGraph g = v1.steps[0];
  g.host_ns = 77;
  EXPECT_EQ(g, v2.steps[0]);
  // A version 2 frame cut before its host time is truncated, not read as version 1.
  EXPECT_READ_ERROR(Buf().raw(file_header(2)).raw(header_frame()).raw(frame(2, payload)).raw(end_frame(1)).b,
                    "u64 host time");
}

// ---- corruption, one class at a time ----------------------------------------------------

TEST(TraceReader, RejectsATruncatedFileHeader) {
  EXPECT_READ_ERROR(Bytes{}, "offset 0: truncated file header: expected 8 bytes");
  EXPECT_READ_ERROR(Bytes({'T', 'G', 'T'}), "found 3");
}

TEST(TraceReader, RejectsBadMagic) {
  Bytes b = trace_of(RawStep{});
  b[0] = 0x89;
  EXPECT_READ_ERROR(b, "offset 0: bad magic: expected \"TGTR\"");
}

TEST(TraceReader, RejectsAnUnsupportedVersion) {
  Bytes b = trace_of(RawStep{});
  b[4] = 3;
  EXPECT_READ_ERROR(b, "offset 4: unsupported format version 3: expected 1 to 2");
  b[4] = 0;
  EXPECT_READ_ERROR(b, "offset 4: unsupported format version 0: expected 1 to 2");
}

TEST(TraceReader, RejectsATruncatedFrame) {
  const Bytes whole = trace_of(RawStep{});
  const std::size_t step_frame = 8 + header_frame().size();
  const Bytes cut(whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(step_frame + 20));
  EXPECT_READ_ERROR(cut, "offset " + std::to_string(step_frame) + ": truncated frame: expected ");
  EXPECT_READ_ERROR(cut, "(0 complete steps; capture interrupted?) — read with recover");
  const Bytes cut_header(whole.begin(),
                         whole.begin() + static_cast<std::ptrdiff_t>(step_frame + 5));
  EXPECT_READ_ERROR(cut_header, "truncated frame header: expected 12 bytes, found 5");
  const Bytes in_header_frame(whole.begin(), whole.begin() + 15);
  EXPECT_READ_ERROR(in_header_frame, "offset 8: truncated header frame");
  EXPECT_NE(read_error(in_header_frame, true), "");  // nothing to recover without a header
}

TEST(TraceReader, RejectsAChecksumMismatch) {
  Bytes b = trace_of(RawStep{});
  const std::size_t step_frame = 8 + header_frame().size();
  b[step_frame + 12 + 5] ^= 0x40;  // a byte inside the payload
  EXPECT_READ_ERROR(
      b, "offset " + std::to_string(step_frame) + ": checksum mismatch: expected CRC-32 0x");
  EXPECT_NE(read_error(b, true).find("checksum mismatch"), std::string::npos);  // not recoverable
  Bytes c = trace_of(RawStep{});
  c[step_frame + 8] ^= 1;  // the stored checksum itself
  EXPECT_READ_ERROR(c, "checksum mismatch");
}

TEST(TraceReader, RejectsAnUnknownFrameType) {
  RawStep s;
  EXPECT_READ_ERROR(
      trace_of({frame(9, Bytes{1, 2, 3})}, 0),
      "unknown frame type 9: expected 1 (header), 2 (full step), 3 (reference step) or 4 (end)");
  EXPECT_READ_ERROR(trace_of({frame(0, Bytes{})}, 0), "unknown frame type 0");
}

TEST(TraceReader, RejectsAbsurdCountsWithoutAllocatingForThem) {
  // Each list's count is replaced by 0xFFFFFFFF in turn.
  RawStep s;
  const Bytes structure = s.structure();
  // Offsets of the counts inside the full-step payload, from the layout in the format doc.
  std::vector<std::pair<std::size_t, std::string>> counts;
  std::size_t at = 0;
  counts.push_back({at, "kinds"});
  at += 4 + (4 + 9) + (4 + 10);
  counts.push_back({at, "objects"});
  at += 4 + 5 + 5;
  counts.push_back({at, "data"});
  at += 4 + (4 + 1 + 12) + (4 + 4 + 12);
  counts.push_back({at, "accesses"});
  at += 4 + 4 * 5;
  counts.push_back({at, "tasks"});
  at += 4 + 2 * 24;
  counts.push_back({at, "loops"});
  at += 4 + 16;
  ASSERT_EQ(at, structure.size());
  counts.push_back({at, "task costs"});
  at += 4 + 16;
  counts.push_back({at, "loop iteration counts"});
  at += 4 + 4;
  counts.push_back({at, "contacts"});
  at += 4 + 8;
  counts.push_back({at, "groups"});
  const Bytes values = s.values();
  ASSERT_EQ(at + 4 + 8 + 8, structure.size() + values.size());  // groups, host time
  for (const auto& [offset, what] : counts) {
    Bytes payload = Buf().raw(structure).raw(values).b;
    for (int i = 0; i < 4; ++i) payload[offset + static_cast<std::size_t>(i)] = 0xFF;
    const Bytes b = trace_of({frame(2, payload)}, 1);
    const std::string msg = read_error(b);
    EXPECT_NE(msg.find("absurd count: expected at most"), std::string::npos) << what << ": " << msg;
    EXPECT_NE(msg.find(what + " in the"), std::string::npos) << msg;
    EXPECT_NE(msg.find("found 4294967295"), std::string::npos) << msg;
    // Reserving first would ask for 4294967295 elements (>= 20 GiB): fatal under the cap.
    if (!kSanitized) {
      EXPECT_EXIT(read_with_memory_cap(b, "absurd count"), ::testing::ExitedWithCode(0), "")
          << what;
    }
  }
  // A string length larger than the frame.
  Bytes payload = Buf().raw(structure).raw(values).b;
  for (int i = 4; i < 8; ++i) payload[static_cast<std::size_t>(i)] = 0xFF;
  EXPECT_READ_ERROR(trace_of({frame(2, payload)}, 1),
                    "absurd count: expected a kind name of at most");
  // The same in the header frame.
  Bytes header =
      Buf().raw(file_header()).raw(frame(1, Buf().u32(0xFFFFFFFFu).b)).raw(end_frame(0)).b;
  EXPECT_READ_ERROR(header, "offset 20: absurd count: expected a scene string of at most 0 bytes");
}

// Each id of a step's tables past the end of the table it points into: one RawStep
// changed in one place, the message naming the table, the bound and the id found.
TEST(TraceReader, RejectsEveryIdOutOfRange) {
  struct Case {
    void (*change)(RawStep&);
    const char* error;
  };
  const Case cases[] = {
      {[](RawStep& s) { s.tasks[0].kind = 2; },
       "id out of range: expected task kind id < 2, found 2"},
      {[](RawStep& s) { s.tasks[1].object = 7; },
       "id out of range: expected task object id < 2 or 4294967295 (none), found 7"},
      {[](RawStep& s) { s.data[0].object = 2; }, "expected datum object id < 2"},
      {[](RawStep& s) { s.contacts = {{0, 5}}; }, "expected contact object id < 2, found 5"},
      {[](RawStep& s) { s.accesses[2].datum = 2; },
       "id out of range: expected access datum id < 2, found 2"},
      {[](RawStep& s) { s.loops[0].condition = 3; },
       "expected loop condition datum id < 2, found 3"},
      {[](RawStep& s) { s.tasks[1].loop = 1; },
       "id out of range: expected task loop id (or 4294967295 for none) < 1, found 1"},
      {[](RawStep& s) { s.loops[0].last = 3; },
       "malformed loop 0: expected first < last <= 2 tasks, found [1, 3)"},
  };
  for (const Case& c : cases) {
    RawStep s;
    c.change(s);
    EXPECT_READ_ERROR(trace_of(s), c.error);
  }
}

TEST(TraceReader, RejectsMalformedLoops) {
  RawStep empty;
  empty.loops[0].first = 2;
  EXPECT_READ_ERROR(trace_of(empty), "malformed loop 0: expected first < last");
  RawStep overlap;
  overlap.loops.push_back({1, 1, 2, 0});
  overlap.iterations.push_back(1);
  EXPECT_READ_ERROR(trace_of(overlap),
                    "malformed loop 1: expected its body to start at or after task 2");
  RawStep unmarked;
  unmarked.tasks[1].loop = kNone;
  EXPECT_READ_ERROR(trace_of(unmarked),
                    "malformed loop 0: expected task 1 in its body to be marked with loop 0");
  RawStep outside;
  outside.tasks[0].loop = 0;
  EXPECT_READ_ERROR(trace_of(outside),
                    "malformed loop 0: expected task 0 marked with it to lie in its body [1, 2)");
  // Deeper rules come from StepGraph::validate().
  RawStep no_read;
  no_read.accesses[3].mode = 1;  // the break task writes but no longer reads the condition
  EXPECT_READ_ERROR(trace_of(no_read),
                    "invalid step 0: loop 0: last body task does not read the condition");
  RawStep zero;
  zero.iterations[0] = 0;
  EXPECT_READ_ERROR(trace_of(zero), "invalid step 0: loop 0: zero iterations");
}

TEST(TraceReader, RejectsAReferenceToANonExistentStep) {
  RawStep s;
  EXPECT_READ_ERROR(
      trace_of({s.full_frame(), s.reference_frame(1)}, 2),
      "reference to a non-existent step: expected an earlier step index < 1, found 1");
  EXPECT_READ_ERROR(trace_of({s.full_frame(), s.reference_frame(0xFFFFFFFFu)}, 2),
                    "found 4294967295");
}

TEST(TraceReader, RejectsAMissingEndFrameUnlessRecovering) {
  RawStep s;
  Bytes b =
      Buf().raw(file_header()).raw(header_frame()).raw(s.full_frame()).raw(s.reference_frame(0)).b;
  EXPECT_READ_ERROR(
      b, "offset " + std::to_string(b.size()) +
             ": trace not closed (2 complete steps; capture interrupted?) — read with recover");
  try {  // the option's field, which a front end names in its words (the command line: --recover)
    read_trace_bytes(b, "t");
  } catch (const InputError& e) {
    const auto flag = [](const std::string& f) { return "--" + f; };
    EXPECT_TRUE(e.render(flag).ends_with("— read with --recover")) << e.what();
  }
  ReadOptions recover;
  recover.recover = true;
  EXPECT_EQ(read_trace_bytes(b, "t", recover).steps.size(), 2u);
  const Bytes header_only = Buf().raw(file_header()).raw(header_frame()).b;
  EXPECT_READ_ERROR(header_only, "trace not closed (0 complete steps;");
  EXPECT_EQ(read_trace_bytes(header_only, "t", recover).steps.size(), 0u);
  EXPECT_READ_ERROR(file_header(), "offset 8: expected a header frame after the file header");
}

TEST(TraceReader, RejectsFramesOutOfPlace) {
  RawStep s;
  EXPECT_READ_ERROR(trace_of({s.full_frame()}, 2), "end frame count mismatch: expected 1 steps");
  Bytes trailing = trace_of(s);
  trailing.push_back(0);
  EXPECT_READ_ERROR(trailing,
                    "expected the end of the file after the end frame, found 1 more bytes");
  EXPECT_READ_ERROR(trace_of({header_frame()}, 0), "found a second header frame");
  const Bytes step_first = Buf().raw(file_header()).raw(s.full_frame()).raw(end_frame(1)).b;
  EXPECT_READ_ERROR(step_first,
                    "offset 8: expected the header frame (type 1) first, found frame type 2");
  const Bytes extra_payload =
      trace_of({frame(2, Buf().raw(s.structure()).raw(s.values()).u8(0).b)}, 1);
  EXPECT_READ_ERROR(extra_payload, "expected the frame payload to end here, found 1 unread bytes");
  const Bytes short_payload = trace_of({frame(2, s.structure())}, 1);
  EXPECT_READ_ERROR(short_payload,
                    "truncated: expected u32 count (4 bytes), the frame has 0 left");
}

TEST(TraceReader, RejectsInconsistentLists) {
  RawStep mode;
  mode.accesses[0].mode = 7;
  EXPECT_READ_ERROR(trace_of(mode), "expected access mode 0..3 (R, W, RW, CW), found 7");
  RawStep sum;
  sum.tasks[1].access_count = 2;
  EXPECT_READ_ERROR(
      trace_of(sum),
      "expected the tasks' access counts to add up to the 4 accesses, they add up to 3");
  RawStep over;
  over.tasks[0].access_count = 5;
  EXPECT_READ_ERROR(trace_of(over),
                    "expected task 0 to own at most the 4 accesses left, found access count 5");
  RawStep costs;
  costs.costs.pop_back();
  EXPECT_READ_ERROR(trace_of(costs), "expected 2 task costs (one per task), found 1");
  RawStep iterations;
  iterations.iterations.push_back(1);
  EXPECT_READ_ERROR(trace_of(iterations),
                    "expected 1 loop iteration counts (one per loop), found 2");
  RawStep groups;
  groups.groups.push_back(0);
  EXPECT_READ_ERROR(trace_of(groups), "expected 0 or 2 collision groups (one per object), found 3");
}

TEST(TraceReader, ErrorsNameTheFileAndTheOffset) {
  try {
    read_trace_bytes(Bytes{'x'}, "some/file.tgt");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "some/file.tgt");
    EXPECT_EQ(e.offset(), 0u);
    EXPECT_EQ(std::string(e.what()).rfind("some/file.tgt: offset 0: ", 0), 0u) << e.what();
  }
  EXPECT_THROW(read_trace("/nonexistent-folder/x.tgt"), InputError);
}

// ---- recovery ---------------------------------------------------------------------------

TEST(TraceReader, RecoversTheCompleteStepsAfterTruncationAtEveryOffset) {
  const Trace trace = make_trace({0, 1, 0, 0});
  const Bytes bytes = encode_trace(trace);
  // Where each frame ends: a prefix holds the steps whose frames end inside it.
  std::vector<std::size_t> frame_end;
  for (std::size_t pos = 8; pos < bytes.size(); pos += 12 + get_u32(bytes, pos + 4))
    frame_end.push_back(pos + 12 + get_u32(bytes, pos + 4));
  ASSERT_EQ(frame_end.size(), 6u);  // header, 4 steps, end
  ReadOptions recover;
  recover.recover = true;
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const Bytes prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    if (n < frame_end[0]) {
      EXPECT_THROW(read_trace_bytes(prefix, "cut", recover), InputError) << n;
      continue;
    }
    std::size_t complete = 0;
    while (complete < 4 && frame_end[1 + complete] <= n) ++complete;
    Trace back;
    ASSERT_NO_THROW(back = read_trace_bytes(prefix, "cut", recover)) << "prefix " << n;
    ASSERT_EQ(back.steps.size(), complete) << "prefix " << n;
    for (std::size_t s = 0; s < complete; ++s) EXPECT_EQ(back.steps[s], trace.steps[s]);
    EXPECT_NE(read_error(prefix).find("read with recover"), std::string::npos) << n;
  }
  EXPECT_EQ(read_trace_bytes(bytes, "whole", recover), trace);
}

// ---- bounded decoding -------------------------------------------------------------------

TEST(TraceReader, BoundsTheMemoryThatReferenceFramesExpandTo) {
  // One step whose structure holds a 256 KiB name, then references repeating it: each
  // 36-byte frame would copy 256 KiB. Decoding stops at 64 MiB + 128 x file size (~100 MB).
  RawStep s;
  s.objects[0] = std::string(256 << 10, 'n');
  std::vector<Bytes> frames{s.full_frame()};
  for (int i = 0; i < 600; ++i) frames.push_back(s.reference_frame(0));
  const Bytes b = trace_of(frames, 601);
  EXPECT_READ_ERROR(b, "decoded trace too large: expected at most");
}

// ---- committed files ----------------------------------------------------------------------

fs::path data_dir() {
#ifdef TGRAPH_TEST_DATA
  return fs::path(TGRAPH_TEST_DATA) / "traces";
#else
  return fs::path(__FILE__).parent_path().parent_path() / "data" / "traces";
#endif
}

TEST(TraceReader, ReadsTheCommittedValidTraces) {
  const Trace small = read_trace((data_dir() / "small.tgt").string());
  EXPECT_EQ(small.header.scene, "hand-made");
  ASSERT_EQ(small.steps.size(), 3u);
  EXPECT_EQ(small.steps[2].loops[0].iterations, 5u);
  EXPECT_TRUE(small.steps[0].same_structure(small.steps[2]));
  EXPECT_EQ(small.steps[1].contacts.size(), 0u);
  EXPECT_EQ(small.steps[0].host_ns, 700u);
  EXPECT_EQ(small.steps[1].host_ns, 0u);
  EXPECT_EQ(small.steps[2].host_ns, 900u);
  // Writing it again gives the committed bytes: the format has not drifted.
  EXPECT_EQ(encode_trace(small), slurp(data_dir() / "small.tgt"));
  // A version 1 file (no host times) reads as the same steps with host_ns 0.
  const Trace v1 = read_trace((data_dir() / "small-v1.tgt").string());
  ASSERT_EQ(v1.steps.size(), small.steps.size());
  for (std::size_t s = 0; s < v1.steps.size(); ++s) {
    EXPECT_EQ(v1.steps[s].host_ns, 0u);
    StepGraph with_host = v1.steps[s];
    with_host.host_ns = small.steps[s].host_ns;
    EXPECT_EQ(with_host, small.steps[s]) << "step " << s;
  }
  EXPECT_EQ(read_trace((data_dir() / "empty.tgt").string()).steps.size(), 0u);
  ReadOptions recover;
  recover.recover = true;
  EXPECT_EQ(read_trace((data_dir() / "interrupted.tgt").string(), recover).steps.size(), 2u);
}

TEST(TraceReader, RejectsEachCommittedBrokenTrace) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bad_magic.tgt", "bad magic"},
      {"bad_version.tgt", "unsupported format version"},
      {"bad_checksum.tgt", "checksum mismatch"},
      {"unknown_frame.tgt", "unknown frame type"},
      {"absurd_count.tgt", "absurd count"},
      {"bad_kind.tgt", "expected task kind id < "},
      {"bad_datum.tgt", "expected access datum id < "},
      {"bad_loop.tgt", "malformed loop 0"},
      {"bad_reference.tgt", "reference to a non-existent step"},
      {"truncated.tgt", "truncated frame"},
      {"interrupted.tgt",
       "trace not closed (2 complete steps; capture interrupted?) — read with recover"},
  };
  for (const auto& [file, substring] : cases) {
    const fs::path p = data_dir() / file;
    try {
      read_trace(p.string());
      ADD_FAILURE() << file << " was accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(p.string() + ": offset ", 0), 0u) << msg;
      EXPECT_NE(msg.find(substring), std::string::npos) << file << ": " << msg;
    }
  }
}

// ---- file_util ----------------------------------------------------------------------------

TEST(FileUtil, WriteFileAtomicReplacesTheWholeFile) {
  const fs::path p = temp_path("atomic.txt");
  write_file_atomic(p.string(), "first version, longer");
  write_file_atomic(p.string(), "second");
  const Bytes b = read_file_bytes(p.string());
  EXPECT_EQ(std::string(b.begin(), b.end()), "second");
  for (const auto& e : fs::directory_iterator(p.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".atomic.txt.tmp"), std::string::npos) << e.path();
}

TEST(FileUtil, ReadFileBytesNamesAMissingFile) {
  try {
    read_file_bytes("/nonexistent-folder/none.bin");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/none.bin: cannot open"),
              std::string::npos);
  }
  EXPECT_THROW(read_file_bytes(::testing::TempDir()), InputError);  // a directory
}

TEST(FileUtil, ReadFileTextReturnsTheBytesAsWritten) {
  const fs::path p = temp_path("text.json");
  const std::string text = std::string("{\"a\": 1}\n") + '\0' + "tail";
  write_file_atomic(p.string(), text);
  EXPECT_EQ(read_file_text(p.string()), text);
  EXPECT_THROW(read_file_text("/nonexistent-folder/none.json"), InputError);
}

TEST(Trace, StepAtNamesTheFieldTheTraceAndItsStepCount) {
  Trace t;
  t.steps.resize(3);
  EXPECT_EQ(&step_at(t, 2, "f.tgt"), &t.steps[2]);
  try {
    step_at(t, 3, "f.tgt");
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "step: trace f.tgt has 3 steps, no step 3");
  }
  try {
    step_at(t, 7, "g.tgt", "steps");
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "steps: trace g.tgt has 3 steps, no step 7");
  }
}

}  // namespace
}  // namespace tgraph
