// SPDX-License-Identifier: MIT
// libFuzzer target: any bytes given to the .tga reader give an assignment or a tgraph::Error;
// one that decodes encodes back to the same bytes.
//
// The whole file is covered by one CRC-32 and a total length: each input is read as given
// and with length and checksum resealed, so that mutations reach the body decoder.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_util.hpp"
#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace {

void read_one(std::span<const std::uint8_t> bytes) {
  try {
    std::vector<std::uint64_t> hashes;
    const tgraph::TraceAssignment a = tgraph::partition::decode_assignment(bytes, "fuzz", &hashes);
    const std::vector<std::uint8_t> again = tgraph::partition::encode_assignment(a, hashes);
    // The format has one encoding per assignment (no padding, no optional fields).
    if (!std::equal(again.begin(), again.end(), bytes.begin(), bytes.end()))
      tgraph::fuzz::invariant_failed();
  } catch (const tgraph::Error&) {
  }
}

std::vector<std::uint8_t> resealed(std::span<const std::uint8_t> in) {
  std::vector<std::uint8_t> b(in.begin(), in.end());
  if (b.size() < 16 + 4) return b;
  tgraph::ByteWriter w(b);
  w.u64_at(8, b.size());
  w.u32_at(b.size() - 4, tgraph::crc32(std::span(b).first(b.size() - 4)));
  return b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  read_one(bytes);
  read_one(resealed(bytes));
  return 0;
}
