// SPDX-License-Identifier: MIT
// Errors for inputs from outside (files, flags, scenes) and internal asserts.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

namespace tgraph {

/// Base of every error tgraph reports about its input; the command line maps it to exit 2.
class Error : public std::runtime_error {
 public:
  /// `what` is the complete one-line message ("file: offset N: expected ...").
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// Malformed or unreadable input file; carries the file and byte offset.
class InputError : public Error {
 public:
  InputError(std::string file, std::optional<std::uint64_t> offset, const std::string& what)
      : Error(format(file, offset, what)), file_(std::move(file)), offset_(offset) {}
  /// File the error is about.
  const std::string& file() const { return file_; }
  /// Byte offset in the file where reading failed, if known.
  std::optional<std::uint64_t> offset() const { return offset_; }

 private:
  static std::string format(const std::string& file, std::optional<std::uint64_t> offset,
                            const std::string& what) {
    std::string s = file.empty() ? std::string("<input>") : file;
    if (offset) s += ": offset " + std::to_string(*offset);
    return s + ": " + what;
  }
  std::string file_;
  std::optional<std::uint64_t> offset_;
};

/// Bad flag or argument combination on the command line or in an API call.
class UsageError : public Error {
 public:
  using Error::Error;
};

}  // namespace tgraph

#if defined(TGRAPH_ENABLE_ASSERT)
#define TGRAPH_ASSERT(cond)                                                           \
  do {                                                                                \
    if (!(cond)) {                                                                    \
      std::fprintf(stderr, "%s:%d: assertion failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                   \
    }                                                                                 \
  } while (0)
#else
#define TGRAPH_ASSERT(cond) ((void)0)
#endif
