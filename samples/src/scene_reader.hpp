// SPDX-License-Identifier: MIT
// Reading a scene file (scene_file.cpp): its lines as directives with typed attributes.
#pragma once

#include <array>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/samples/state.hpp"

namespace tgraph::samples::detail {

/// One line of a scene file: a keyword and key=value attributes; the accessors read an
/// attribute (marking it used) and throw InputError naming the file and line.
class Directive {
 public:
  Directive(std::string file, int line, std::string keyword, std::map<std::string, std::string> attrs)
      : file_(std::move(file)), line_(line), keyword_(std::move(keyword)), attrs_(std::move(attrs)) {}

  const std::string& keyword() const { return keyword_; }
  int line() const { return line_; }

  [[noreturn]] void fail(const std::string& what) const;
  bool has(const std::string& key) const { return attrs_.count(key) != 0; }

  std::string text(const std::string& key, std::optional<std::string> def = std::nullopt);
  double number(const std::string& key, std::optional<double> def = std::nullopt);
  double positive(const std::string& key, std::optional<double> def = std::nullopt);
  double non_negative(const std::string& key, std::optional<double> def = std::nullopt);
  int integer(const std::string& key, std::optional<int> def, int lo, int hi);
  std::vector<double> numbers(const std::string& key, std::size_t count, const std::string& s);
  Vec3 vec3(const std::string& key, std::optional<Vec3> def = std::nullopt);
  std::array<int, 3> int3(const std::string& key, std::optional<std::array<int, 3>> def, int lo, int hi);
  std::string choice(const std::string& key, const std::string& def, std::initializer_list<const char*> allowed);

  // Every attribute must have been consumed.
  void finish() const;

 private:
  double parse_number(const std::string& key, const std::string& s) const;
  std::string file_;
  int line_;
  std::string keyword_;
  std::map<std::string, std::string> attrs_;
  std::set<std::string> used_;
};

/// Reads `text` (a scene file named `file` in messages): checks the 'tgraph-scene 1' header
/// and calls `on_directive` for every later line that has a keyword, then checks that every
/// attribute was used. Returns the number of the last line.
int read_directives(std::string_view text, const std::string& file,
                    const std::function<void(Directive&)>& on_directive);

}  // namespace tgraph::samples::detail
