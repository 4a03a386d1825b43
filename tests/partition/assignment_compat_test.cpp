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

// `f` holds `k` processors and `method` over three steps, and encodes back to its bytes.
void expect_three_steps_encoded_back(const OldFile& f, std::uint32_t k, const std::string& method) {
  EXPECT_EQ(f.a.k, k);
  EXPECT_EQ(f.a.method, method);
  EXPECT_EQ(f.a.steps.size(), 3u);
  EXPECT_EQ(encode_assignment(f.a, f.hashes), f.bytes);
}

TEST(AssignmentCompat, CrcIsZlibsCrc32) {
  const std::string text = "123456789";
  const std::vector<std::uint8_t> b(text.begin(), text.end());
  EXPECT_EQ(crc32(b), 0xCBF43926u);  // the check value of CRC-32/ISO-HDLC
  EXPECT_EQ(crc32(std::span(b).subspan(4), crc32(std::span(b).first(4))), 0xCBF43926u);
}

TEST(AssignmentCompat, ReadsAnOwnerAssignmentWrittenBeforeTheSharedCodec) {
  const OldFile f = read_old("small_owner_k2.tga");
  expect_three_steps_encoded_back(f, 2, "owner");
  for (const Assignment& s : f.a.steps) {
    EXPECT_EQ(s.k, 2u);
    EXPECT_TRUE(s.order.empty());
    for (const ProcId p : s.proc) EXPECT_LT(p, 2u);
  }
}

TEST(AssignmentCompat, ReadsAListAssignmentWithOrdersWrittenBeforeTheSharedCodec) {
  const OldFile f = read_old("small_list_k3.tga");
  expect_three_steps_encoded_back(f, 3, "list");
  for (const Assignment& s : f.a.steps) {
    ASSERT_EQ(s.order.size(), 3u);
    std::size_t listed = 0;
    for (const auto& o : s.order) listed += o.size();
    EXPECT_EQ(listed, s.proc.size());
  }
  for (const std::uint64_t h : f.hashes) EXPECT_NE(h, 0u);
}

}  // namespace
}  // namespace tgraph::partition
