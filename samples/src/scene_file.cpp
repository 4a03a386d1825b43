// SPDX-License-Identifier: MIT
// Scene files (format: samples/scenes/README.md) and the built-in scenes: finding a scene's
// text, reading its lines as directives; SceneBuilder (scene_builder.cpp) builds the scene.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "builtin_scenes.hpp"
#include "scene_builder.hpp"
#include "scene_reader.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {

namespace detail {

void Directive::fail(const std::string& what) const {
  throw InputError(file_ + ":" + std::to_string(line_), std::nullopt, what);
}

std::string Directive::text(const std::string& key, std::optional<std::string> def) {
  auto it = attrs_.find(key);
  if (it == attrs_.end()) {
    if (!def) fail("'" + keyword_ + "' needs " + key + "=...");
    return *def;
  }
  used_.insert(key);
  return it->second;
}

double Directive::number(const std::string& key, std::optional<double> def) {
  if (!has(key)) {
    if (!def) fail("'" + keyword_ + "' needs " + key + "=<number>");
    return *def;
  }
  return parse_number(key, text(key));
}

double Directive::positive(const std::string& key, std::optional<double> def) {
  const double v = number(key, def);
  if (!(v > 0.0)) fail(key + " must be > 0 (got " + text(key, std::to_string(v)) + ")");
  return v;
}

double Directive::non_negative(const std::string& key, std::optional<double> def) {
  const double v = number(key, def);
  if (!(v >= 0.0)) fail(key + " must be >= 0");
  return v;
}

int Directive::integer(const std::string& key, std::optional<int> def, int lo, int hi) {
  if (!has(key)) {
    if (!def) fail("'" + keyword_ + "' needs " + key + "=<integer>");
    return *def;
  }
  const std::string s = text(key);
  int v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size()) fail(key + ": '" + s + "' is not an integer");
  if (v < lo || v > hi) fail(key + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

std::vector<double> Directive::numbers(const std::string& key, std::size_t count, const std::string& s) {
  std::vector<double> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    const std::size_t comma = s.find(',', start);
    const std::string part = s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    out.push_back(parse_number(key, part));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (count != 0 && out.size() != count)
    fail(key + ": expected " + std::to_string(count) + " comma-separated numbers, got " + std::to_string(out.size()));
  return out;
}

Vec3 Directive::vec3(const std::string& key, std::optional<Vec3> def) {
  if (!has(key)) {
    if (!def) fail("'" + keyword_ + "' needs " + key + "=x,y,z");
    return *def;
  }
  const auto v = numbers(key, 3, text(key));
  return {v[0], v[1], v[2]};
}

std::array<int, 3> Directive::int3(const std::string& key, std::optional<std::array<int, 3>> def, int lo, int hi) {
  if (!has(key)) {
    if (!def) fail("'" + keyword_ + "' needs " + key + "=a,b,c");
    return *def;
  }
  const auto v = numbers(key, 3, text(key));
  std::array<int, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    if (v[i] != std::floor(v[i]) || v[i] < lo || v[i] > hi)
      fail(key + ": each value must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    out[i] = static_cast<int>(v[i]);
  }
  return out;
}

std::string Directive::choice(const std::string& key, const std::string& def, std::initializer_list<const char*> allowed) {
  const std::string v = text(key, def);
  for (const char* a : allowed)
    if (v == a) return v;
  std::string list;
  for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
  fail(key + ": '" + v + "' is not one of " + list);
}

void Directive::finish() const {
  for (const auto& [k, v] : attrs_)
    if (used_.count(k) == 0) fail("unknown attribute '" + k + "' for '" + keyword_ + "'");
}

double Directive::parse_number(const std::string& key, const std::string& s) const {
  double v = 0.0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty() || !std::isfinite(v))
    fail(key + ": '" + s + "' is not a number");
  return v;
}

int read_directives(std::string_view text, const std::string& file,
                    const std::function<void(Directive&)>& on_directive) {
  std::istringstream in{std::string(text)};
  std::string line;
  int number = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++number;
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword)) continue;
    std::map<std::string, std::string> attrs;
    std::vector<std::string> positional;
    std::string word;
    while (words >> word) {
      const auto eq = word.find('=');
      if (eq == std::string::npos) {
        positional.push_back(word);
        continue;
      }
      const std::string key = word.substr(0, eq);
      if (key.empty()) Directive(file, number, keyword, {}).fail("attribute with an empty name");
      if (!attrs.emplace(key, word.substr(eq + 1)).second)
        Directive(file, number, keyword, {}).fail("attribute '" + key + "' given twice");
    }
    Directive d(file, number, keyword, std::move(attrs));
    if (!header) {
      if (keyword != "tgraph-scene" || positional.size() != 1 || positional[0] != "1")
        d.fail("the first line must be 'tgraph-scene 1'");
      header = true;
      continue;
    }
    if (!positional.empty()) d.fail("'" + positional[0] + "' is not a key=value attribute");
    on_directive(d);
    d.finish();
  }
  if (!header) Directive(file, number, "", {}).fail("empty scene file (the first line must be 'tgraph-scene 1')");
  return number;
}

}  // namespace detail
std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < detail::kBuiltinSceneCount; ++i) out.emplace_back(detail::kBuiltinScenes[i].name);
  return out;
}

std::optional<std::string_view> builtin_scene_text(std::string_view name) {
  for (std::size_t i = 0; i < detail::kBuiltinSceneCount; ++i)
    if (name == detail::kBuiltinScenes[i].name) return std::string_view(detail::kBuiltinScenes[i].text);
  return std::nullopt;
}

std::unique_ptr<Scene> parse_scene(std::string_view text, std::string_view file, const SceneOptions& options) {
  return detail::SceneBuilder(std::string(file), options).build(text);
}

std::unique_ptr<Scene> make_scene(std::string_view name_or_path, const SceneOptions& options) {
  if (auto text = builtin_scene_text(name_or_path)) return parse_scene(*text, std::string(name_or_path), options);
  const std::string path(name_or_path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string names;
    for (const auto& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError(path, std::nullopt, "no such scene file, and not a built-in scene (" + names + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::nullopt, "cannot open the scene file");
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  if (text.size() > (64u << 20)) throw InputError(path, std::nullopt, "scene file larger than 64 MiB");
  return parse_scene(text, path, options);
}

}  // namespace tgraph::samples
