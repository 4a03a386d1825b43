// SPDX-License-Identifier: MIT
// .tga round trip and every class of bad file.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "tgraph/graph/error.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/strategy.hpp"
#include "test_graphs.hpp"

namespace tgraph::partition {
namespace {

TraceAssignment sample() {
  TraceAssignment a;
  a.method = "list";
  a.k = 3;
  Assignment s0;
  s0.k = 3;
  s0.proc = {0, 1, 2, 1, 0};
  Assignment s1;
  s1.k = 3;
  s1.proc = {2, 2, 0, 1};
  s1.order = {{2}, {3}, {1, 0}};
  a.steps = {s0, s1};
  a.partition_ms = {0.25, 1.5};
  return a;
}

std::string message_of(const std::vector<std::uint8_t>& bytes) {
  try {
    decode_assignment(bytes, "bad.tga");
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "bad.tga");
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

// Recomputes the trailing CRC-32 after a deliberate edit (to reach the checks behind it).
void reseal(std::vector<std::uint8_t>& b) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i + 4 < b.size(); ++i) {
    c ^= b[i];
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  c ^= 0xFFFFFFFFu;
  std::memcpy(b.data() + b.size() - 4, &c, 4);
}

TEST(AssignmentFile, RoundTripsStepsOrdersTimesAndHashes) {
  const TraceAssignment a = sample();
  std::vector<std::uint64_t> hashes;
  const TraceAssignment back = decode_assignment(encode_assignment(a, {11, 22}), "x.tga", &hashes);
  EXPECT_EQ(back, a);
  EXPECT_EQ(hashes, (std::vector<std::uint64_t>{11, 22}));
}

TEST(AssignmentFile, RoundTripsThroughAFile) {
  const std::string path = (std::filesystem::temp_directory_path() / "tgraph_partition_test.tga").string();
  write_assignment(path, sample());
  EXPECT_EQ(read_assignment(path), sample());
  std::filesystem::remove(path);
  EXPECT_THROW(read_assignment(path), InputError);
}

TEST(AssignmentFile, RejectsEveryTruncation) {
  const std::vector<std::uint8_t> full = encode_assignment(sample());
  for (std::size_t n = 0; n < full.size(); ++n) {
    const std::vector<std::uint8_t> cut(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
    const std::string m = message_of(cut);
    EXPECT_NE(m.find("truncated"), std::string::npos) << n << ": " << m;
  }
}

TEST(AssignmentFile, RejectsABadChecksum) {
  std::vector<std::uint8_t> b = encode_assignment(sample());
  b[b.size() / 2] ^= 0x10;
  const std::string m = message_of(b);
  EXPECT_NE(m.find("checksum"), std::string::npos) << m;
  EXPECT_NE(m.find("offset"), std::string::npos) << m;
}

TEST(AssignmentFile, RejectsAnotherVersionAndAnotherFormat) {
  std::vector<std::uint8_t> b = encode_assignment(sample());
  b[4] = 9;
  EXPECT_NE(message_of(b).find("unsupported version 9"), std::string::npos);
  b = encode_assignment(sample());
  b[0] = 'X';
  EXPECT_NE(message_of(b).find("magic"), std::string::npos);
  b = encode_assignment(sample());
  b.push_back(0);
  EXPECT_NE(message_of(b).find("expected end of file"), std::string::npos);
}

TEST(AssignmentFile, RejectsZeroProcessors) {
  TraceAssignment a = sample();
  a.k = 0;
  for (auto& s : a.steps) s.order.clear();
  EXPECT_NE(message_of(encode_assignment(a)).find("expected k in [1,"), std::string::npos);
}

TEST(AssignmentFile, RejectsAProcessorOutOfRange) {
  TraceAssignment a = sample();
  a.steps[0].proc[3] = 3;
  const std::string m = message_of(encode_assignment(a));
  EXPECT_NE(m.find("task 3 on processor 3, expected < k = 3"), std::string::npos) << m;
}

TEST(AssignmentFile, RejectsAnOrderThatIsNotAPermutationOfTheProcessorsTasks) {
  TraceAssignment a = sample();
  a.steps[1].order = {{2}, {3}, {1, 1}};
  EXPECT_NE(message_of(encode_assignment(a)).find("order of processor 2"), std::string::npos);
  a.steps[1].order = {{2}, {0}, {1, 3}};
  EXPECT_NE(message_of(encode_assignment(a)).find("order of processor 1"), std::string::npos);
}

TEST(AssignmentFile, RejectsAbsurdCountsWithoutAllocating) {
  std::vector<std::uint8_t> b = encode_assignment(sample());
  // Step count (at offset 20) set to 2^32 - 1.
  std::memset(b.data() + 20, 0xFF, 4);
  reseal(b);
  EXPECT_NE(message_of(b).find("step count"), std::string::npos);
  b = encode_assignment(sample());
  // Task count of step 0: after magic, version, length, k, steps, method length, "list".
  std::memset(b.data() + 32, 0xFF, 4);
  reseal(b);
  EXPECT_NE(message_of(b).find("exceeds the file"), std::string::npos);
}

TEST(AssignmentFile, LoadsOnlyForTheTraceItWasMadeFor) {
  Trace trace, other;
  trace.steps = {testing::objects_scene(6, {}), testing::objects_scene(6, {{1, 2}})};
  // Same task counts, another structure at step 1 (another contact).
  other.steps = {testing::objects_scene(6, {}), testing::objects_scene(6, {{3, 4}})};
  const TracePartition tp = partition_trace(trace, "owner", 2);
  const std::string path = (std::filesystem::temp_directory_path() / "tgraph_load_assignment.tga").string();
  write_assignment(path, tp.assignment, trace);
  EXPECT_EQ(load_assignment(path, trace, "t.tgt"), tp.assignment);
  try {
    load_assignment(path, other, "o.tgt");
    ADD_FAILURE() << "accepted an assignment made for another structure";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": step 1 was partitioned for a graph of another structure than o.tgt's");
  }
  Trace shorter;
  shorter.steps = {trace.steps[0]};
  EXPECT_THROW(load_assignment(path, shorter, "s.tgt"), InputError);
  std::filesystem::remove(path);
}

TEST(AssignmentFile, LoadOrPartitionChecksTheThreadCount) {
  Trace trace;
  trace.steps = {testing::objects_scene(6, {}), testing::objects_scene(6, {{1, 2}})};
  const TraceAssignment computed = load_or_partition(trace, "t.tgt", "", "owner", 2);
  EXPECT_EQ(computed.k, 2u);
  EXPECT_EQ(computed.steps, partition_trace(trace, "owner", 2).assignment.steps);
  const std::string path =
      (std::filesystem::temp_directory_path() / "tgraph_load_or_partition.tga").string();
  write_assignment(path, computed, trace);
  EXPECT_EQ(load_or_partition(trace, "t.tgt", path, "metis", 2), computed);  // the file wins
  try {
    load_or_partition(trace, "t.tgt", path, "owner", 3);
    ADD_FAILURE() << "accepted K = 2 on 3 threads";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "threads: 3 does not fit " + path + ": assignment has k = 2");
  }
  for (const std::string& p : {std::string(), path}) {
    try {
      load_or_partition(trace, "t.tgt", p, "owner", 0);
      ADD_FAILURE() << "accepted 0 threads";
    } catch (const UsageError& e) {
      EXPECT_STREQ(e.what(), "threads: must be at least 1");
    }
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace tgraph::partition
