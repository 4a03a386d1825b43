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

/// A bad value or combination of an API call's options, named by the options' fields, not
/// by a command line's words: the modules know fields, the front ends (apps/, Python) know
/// their flags. `option` is the field at fault (snake_case, e.g. "threads"); `problem` may
/// name other fields as `{field}`. what() is "threads: must be at least 1", each `{field}`
/// written as the bare field name; a front end writes it in its own words with render().
class OptionError : public UsageError {
 public:
  OptionError(std::string option, std::string problem)
      : UsageError(render_with(option, problem, [](const std::string& f) { return f; })),
        option_(std::move(option)),
        problem_(std::move(problem)) {}
  /// The field at fault.
  const std::string& option() const { return option_; }
  /// The problem, with `{field}` where it names another field.
  const std::string& problem() const { return problem_; }
  /// "<name(option)>: <problem>", every `{field}` of the problem replaced by name(field).
  template <class Name>
  std::string render(const Name& name) const {
    return render_with(option_, problem_, name);
  }

 private:
  template <class Name>
  static std::string render_with(const std::string& option, const std::string& problem,
                                 const Name& name) {
    std::string s = name(option) + ": ";
    for (std::size_t i = 0; i < problem.size(); ++i) {
      const std::size_t close = problem[i] == '{' ? problem.find('}', i) : std::string::npos;
      if (close == std::string::npos) {
        s += problem[i];
        continue;
      }
      s += name(problem.substr(i + 1, close - i - 1));
      i = close;
    }
    return s;
  }
  std::string option_;
  std::string problem_;
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
