// SPDX-License-Identifier: MIT
// Little-endian fields and zlib's CRC-32 for the binary file formats.
#include "tgraph/graph/byte_codec.hpp"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

#include "tgraph/graph/error.hpp"

namespace tgraph {

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) {
  // zlib's crc32() takes a 32-bit length: feed large spans in pieces.
  constexpr std::size_t kPiece = std::size_t{1} << 30;
  uLong c = crc;
  for (std::size_t at = 0; at < bytes.size(); at += kPiece) {
    const std::size_t n = std::min(kPiece, bytes.size() - at);
    c = ::crc32(c, bytes.data() + at, static_cast<uInt>(n));
  }
  return static_cast<std::uint32_t>(c);
}

void ByteWriter::f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }

void ByteWriter::count(std::size_t n, const char* what) {
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw UsageError(std::string("cannot encode more than 2^32-1 ") + what);
  u32(static_cast<std::uint32_t>(n));
}

void ByteWriter::str(std::string_view s) {
  count(s.size(), "bytes in a string");
  bytes(s);
}

void ByteWriter::u32_at(std::size_t at, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) out_[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

void ByteWriter::u64_at(std::size_t at, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) out_[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

ByteReader::ByteReader(std::span<const std::uint8_t> file, std::size_t begin, std::size_t end,
                       const std::string& name, const char* region)
    : file_(file), pos_(begin), end_(end), name_(name), region_(region) {
  TGRAPH_ASSERT(begin <= end && end <= file.size());
}

void ByteReader::fail(std::uint64_t offset, const std::string& what) const {
  throw InputError(name_, offset, what);
}

void ByteReader::need(std::size_t n, const char* what) {
  if (left() < n)
    fail(pos_, std::string("truncated: expected ") + what + " (" + std::to_string(n) + " bytes), " +
                   region_ + " has " + std::to_string(left()) + " left");
}

std::uint8_t ByteReader::u8(const char* what) {
  need(1, what);
  return file_[pos_++];
}

std::uint32_t ByteReader::u32(const char* what) {
  need(4, what);
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= std::uint32_t{file_[pos_ + i]} << (8 * i);
  pos_ += 4;
  return v;
}

std::uint64_t ByteReader::u64(const char* what) {
  need(8, what);
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v |= std::uint64_t{file_[pos_ + i]} << (8 * i);
  pos_ += 8;
  return v;
}

double ByteReader::f64(const char* what) { return std::bit_cast<double>(u64(what)); }

std::string ByteReader::bytes(std::size_t n, const char* what) {
  need(n, what);
  std::string s(reinterpret_cast<const char*>(file_.data() + pos_), n);
  pos_ += n;
  return s;
}

std::uint32_t ByteReader::count(const char* what, std::uint64_t min_size, std::uint64_t ceiling) {
  const std::size_t at = pos_;
  const std::uint32_t n = u32("u32 count");
  const std::uint64_t fits = left() / std::max<std::uint64_t>(min_size, 1);
  if (n > fits)
    fail(at, std::string("absurd count: expected at most ") + std::to_string(fits) + " " + what +
                 " in the " + std::to_string(left()) + " bytes left in " + region_ + ", found " +
                 std::to_string(n));
  if (n > ceiling)
    fail(at, std::string("absurd count: expected at most ") + std::to_string(ceiling) + " " + what +
                 " (the format's limit), found " + std::to_string(n));
  return n;
}

std::string ByteReader::str(const char* what, std::uint64_t max_length) {
  const std::size_t at = pos_;
  const std::uint32_t n = u32("u32 string length");
  if (n > left())
    fail(at, std::string("absurd count: expected a ") + what + " of at most " +
                 std::to_string(left()) + " bytes (left in " + region_ + "), found length " +
                 std::to_string(n));
  if (n > max_length)
    fail(at, std::string("expected a ") + what + " of at most " + std::to_string(max_length) +
                 " bytes, found length " + std::to_string(n));
  return bytes(n, what);
}

void ByteReader::expect_end(const char* what) {
  if (pos_ != end_)
    fail(pos_, std::string("expected ") + what + " to end here, found " +
                   std::to_string(end_ - pos_) + " unread bytes");
}

}  // namespace tgraph
