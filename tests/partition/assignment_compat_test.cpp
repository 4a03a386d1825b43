// SPDX-License-Identifier: MIT
// .tga files written before the shared byte codec (tests/data/assignments/) still read, and
// encode back to the same bytes: same layout, same CRC-32 polynomial.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace tgraph::partition {
namespace {

// tests/data/assignments (the build passes the source tree's tests/data).
const std::filesystem::path kDir = std::filesystem::path(TGRAPH_TEST_DATA) / "assignments";

// One file of kDir: its bytes, the assignment decoded from them and the step hashes read.
struct OldFile {
  std::vector<std::uint8_t> bytes;
  std::vector<std::uint64_t> hashes;
  TraceAssignment a;
};

OldFile read_old(const std::string& name) {
  OldFile f;
  f.bytes = read_file_bytes((kDir / name).string());
  f.a = decode_assignment(f.bytes, name, &f.hashes);
  return f;
}

TEST(AssignmentCompat, CrcIsZlibsCrc32) {
  const std::string text = "123456789";
  const std::vector<std::uint8_t> b(text.begin(), text.end());
  EXPECT_EQ(crc32(b), 0xCBF43926u);  // the check value of CRC-32/ISO-HDLC
  EXPECT_EQ(crc32(std::span(b).subspan(4), crc32(std::span(b).first(4))), 0xCBF43926u);
}

TEST(AssignmentCompat, ReadsAnOwnerAssignmentWrittenBeforeTheSharedCodec) {
  const auto [bytes, hashes, a] = read_old("small_owner_k2.tga");
  EXPECT_EQ(a.k, 2u);
  EXPECT_EQ(a.method, "owner");
  ASSERT_EQ(a.steps.size(), 3u);
  for (const Assignment& s : a.steps) {
    EXPECT_EQ(s.k, 2u);
    EXPECT_TRUE(s.order.empty());
    for (const ProcId p : s.proc) EXPECT_LT(p, 2u);
  }
  EXPECT_EQ(encode_assignment(a, hashes), bytes);
}

TEST(AssignmentCompat, ReadsAListAssignmentWithOrdersWrittenBeforeTheSharedCodec) {
  const auto [bytes, hashes, a] = read_old("small_list_k3.tga");
  EXPECT_EQ(a.k, 3u);
  EXPECT_EQ(a.method, "list");
  ASSERT_EQ(a.steps.size(), 3u);
  for (const Assignment& s : a.steps) {
    ASSERT_EQ(s.order.size(), 3u);
    std::size_t listed = 0;
    for (const auto& o : s.order) listed += o.size();
    EXPECT_EQ(listed, s.proc.size());
  }
  for (const std::uint64_t h : hashes) EXPECT_NE(h, 0u);
  EXPECT_EQ(encode_assignment(a, hashes), bytes);
}

}  // namespace
}  // namespace tgraph::partition
