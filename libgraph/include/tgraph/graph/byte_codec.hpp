// SPDX-License-Identifier: MIT
// Little-endian byte encoding shared by the binary files (.tgt traces, .tga assignments).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tgraph {

/// CRC-32 of `bytes` continuing `crc` (0 to start): zlib's crc32(), the polynomial of PNG and
/// Ethernet (reflected 0xEDB88320, initial value and final XOR 0xFFFFFFFF).
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0);

/// Appends little-endian fields to a byte vector.
///
///   std::vector<std::uint8_t> out;
///   ByteWriter w(out);
///   w.u32(7);
///   w.str("name");  // u32 length + bytes
class ByteWriter {
 public:
  /// Appends to `out` (not owned).
  explicit ByteWriter(std::vector<std::uint8_t>& out) : out_(out) {}
  /// One byte.
  void u8(std::uint8_t v) { out_.push_back(v); }
  /// Four bytes, little-endian.
  void u32(std::uint32_t v) { put(v, 4); }
  /// Eight bytes, little-endian.
  void u64(std::uint64_t v) { put(v, 8); }
  /// An IEEE 754 double as its eight bytes, little-endian.
  void f64(double v);
  /// Raw bytes, no length.
  void bytes(std::string_view s) { out_.insert(out_.end(), s.begin(), s.end()); }
  /// A list length as u32; throws UsageError naming `what` if it does not fit.
  void count(std::size_t n, const char* what);
  /// A string as u32 length + bytes.
  void str(std::string_view s);
  /// Overwrites four bytes at `at` (a field reserved earlier).
  void u32_at(std::size_t at, std::uint32_t v);
  /// Overwrites eight bytes at `at`.
  void u64_at(std::size_t at, std::uint64_t v);
  /// Bytes in the vector.
  std::size_t size() const { return out_.size(); }

 private:
  void put(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  std::vector<std::uint8_t>& out_;
};

/// Reads little-endian fields from bytes [begin, end) of a file held in memory. Every read
/// is bounds-checked; failures throw InputError naming the file, the absolute offset of the
/// field and what was expected. Counts are checked against the bytes left and a ceiling
/// before the caller allocates anything.
class ByteReader {
 public:
  /// `file` is the whole file (offsets in errors are relative to its start); `region` names
  /// the part being read in messages ("the frame", "the file").
  ByteReader(std::span<const std::uint8_t> file, std::size_t begin, std::size_t end,
             const std::string& name, const char* region);

  /// Offset of the next field in the file.
  std::size_t pos() const { return pos_; }
  /// Bytes left before `end`.
  std::size_t left() const { return end_ - pos_; }
  /// Name of the file, as given.
  const std::string& name() const { return name_; }

  /// One byte.
  std::uint8_t u8(const char* what);
  /// Four bytes, little-endian.
  std::uint32_t u32(const char* what);
  /// Eight bytes, little-endian.
  std::uint64_t u64(const char* what);
  /// An IEEE 754 double.
  double f64(const char* what);
  /// `n` raw bytes.
  std::string bytes(std::size_t n, const char* what);
  /// A u32 list length whose elements take at least `min_size` bytes each: at most the bytes
  /// left / min_size and at most `ceiling`.
  std::uint32_t count(const char* what, std::uint64_t min_size, std::uint64_t ceiling = UINT32_MAX);
  /// A string stored as u32 length + bytes; the length is checked against the bytes left
  /// and `max_length`.
  std::string str(const char* what, std::uint64_t max_length = UINT32_MAX);
  /// Fails unless every byte up to `end` has been read.
  void expect_end(const char* what);
  /// Throws InputError at `offset` with `what` ("expected ...").
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const;

 private:
  void need(std::size_t n, const char* what);
  std::span<const std::uint8_t> file_;
  std::size_t pos_;
  std::size_t end_;
  const std::string& name_;
  const char* region_;
};

}  // namespace tgraph
