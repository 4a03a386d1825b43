// SPDX-License-Identifier: MIT
// Errors for inputs from outside (files, flags, scenes) and internal asserts.
#pragma once

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

namespace tgraph {

/// Tag of the constructors whose message names options' fields as `{field}`.
struct NamesFields {
  explicit NamesFields() = default;
};
/// The tag: `InputError(file, offset, "... read with {recover}", kNamesFields)`.
inline constexpr NamesFields kNamesFields{};

/// `text` with each `{field}` (a snake_case field name: letters, digits, `_`) written as
/// name(field); any other brace is text.
template <class Name>
std::string name_fields(const std::string& text, const Name& name) {
  std::string s;
  for (std::size_t i = 0; i < text.size(); ++i) {
    std::size_t close = text[i] == '{' ? i + 1 : std::string::npos;
    while (close < text.size() && (std::islower(static_cast<unsigned char>(text[close])) ||
                                   std::isdigit(static_cast<unsigned char>(text[close])) ||
                                   text[close] == '_'))
      ++close;
    if (close >= text.size() || text[close] != '}') {
      s += text[i];
      continue;
    }
    s += name(text.substr(i + 1, close - i - 1));
    i = close;
  }
  return s;
}

/// An exception whose message may name options' fields (snake_case, as the options struct
/// spells them) as `{field}`: what() writes each as the bare field name, a front end in its
/// own words with render() (the command line: as its flag). Base of the Error family and of
/// the failures of a module's work that point at an option (samples::CaptureFailure).
class ErrorWithFields : public std::runtime_error {
 public:
  /// `what` names no field: its braces are text.
  explicit ErrorWithFields(const std::string& what) : std::runtime_error(what), prefix_(what) {}
  /// `prefix` as it is (a file name, a value from outside), then `problem`, which names
  /// fields as `{field}`.
  ErrorWithFields(const std::string& prefix, const std::string& problem, NamesFields)
      : std::runtime_error(prefix + name_fields(problem, [](const std::string& f) { return f; })),
        prefix_(prefix),
        problem_(problem) {}
  /// The message with every `{field}` replaced by name(field).
  template <class Name>
  std::string render(const Name& name) const {
    return prefix_ + name_fields(problem_, name);
  }

 private:
  std::string prefix_, problem_;
};

/// Base of every error tgraph reports about its input; the command line maps it to exit 2.
/// `what` is the complete one-line message ("file: offset N: expected ..."); with the
/// NamesFields tag, a prefix and a problem naming fields (ErrorWithFields).
class Error : public ErrorWithFields {
 public:
  using ErrorWithFields::ErrorWithFields;
};

/// Malformed or unreadable input file; carries the file and byte offset.
class InputError : public Error {
 public:
  InputError(std::string file, std::optional<std::uint64_t> offset, const std::string& what)
      : Error(format(file, offset, what)), file_(std::move(file)), offset_(offset) {}
  /// The same, `problem` naming options' fields as `{field}` ("... read with {recover}").
  InputError(std::string file, std::optional<std::uint64_t> offset, const std::string& problem,
             NamesFields)
      : Error(format(file, offset, ""), problem, kNamesFields),
        file_(std::move(file)),
        offset_(offset) {}
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
      : UsageError("", "{" + option + "}: " + problem, kNamesFields),
        option_(std::move(option)),
        problem_(std::move(problem)) {}
  /// The field at fault.
  const std::string& option() const { return option_; }
  /// The problem, with `{field}` where it names another field.
  const std::string& problem() const { return problem_; }

 private:
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
