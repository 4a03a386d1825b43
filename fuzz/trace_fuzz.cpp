// SPDX-License-Identifier: MIT
// libFuzzer target: any bytes given to the trace reader give a trace or a tgraph::Error.
//
// Random mutations almost never keep a frame's CRC-32 right, so each input is read twice:
// as given (exercising framing and checksums) and with every complete frame's checksum
// recomputed (exercising the payload decoder behind them).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_util.hpp"
#include "tgraph/graph/byte_codec.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace {

constexpr std::size_t kFileHeaderSize = 8;
constexpr std::size_t kFrameHeaderSize = 12;

std::uint32_t load_u32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

std::vector<std::uint8_t> with_fixed_checksums(std::span<const std::uint8_t> in) {
  std::vector<std::uint8_t> b(in.begin(), in.end());
  std::size_t pos = kFileHeaderSize;
  while (pos <= b.size() && b.size() - pos >= kFrameHeaderSize) {
    const std::uint32_t length = load_u32(&b[pos + 4]);
    if (length > b.size() - pos - kFrameHeaderSize) break;
    const std::uint32_t crc = tgraph::crc32(std::span(b).subspan(pos + kFrameHeaderSize, length),
                                            tgraph::crc32(std::span(b).subspan(pos, 8)));
    tgraph::ByteWriter(b).u32_at(pos + 8, crc);
    pos += kFrameHeaderSize + length;
  }
  return b;
}

void read_one(std::span<const std::uint8_t> bytes) {
  for (const bool recover : {false, true}) {
    tgraph::ReadOptions options;
    options.recover = recover;
    try {
      const tgraph::Trace trace = tgraph::read_trace_bytes(bytes, "fuzz", options);
      // Whatever reads back must encode and read back to itself.
      const std::vector<std::uint8_t> again = tgraph::encode_trace(trace);
      if (!(tgraph::read_trace_bytes(again, "fuzz-again") == trace))
        tgraph::fuzz::invariant_failed();
    } catch (const tgraph::Error&) {
      // Expected for malformed input; anything else escapes and is reported.
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  read_one(bytes);
  read_one(with_fixed_checksums(bytes));
  return 0;
}
