// SPDX-License-Identifier: MIT
// Standard Task Graph Set import (https://www.kasahara.cs.waseda.ac.jp/schedule/).
#include "tgraph/graph/stg.hpp"

#include <charconv>
#include <nlohmann/json.hpp>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/json_util.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph {

namespace {

// Ceilings (the largest graphs of the Standard Task Graph Set have 5,000 tasks and about
// 100,000 edges); each edge becomes a datum of about 100 bytes of memory.
constexpr std::uint64_t kMaxTasks = 1u << 24;
constexpr std::uint64_t kMaxEdges = 1u << 24;

class Tokens {
 public:
  Tokens(std::string_view text, const std::string& name) : s_(text), name_(name) {}

  std::size_t offset() const { return pos_; }

  // Next unsigned integer before the trailer; throws naming what was expected.
  std::uint64_t number(const char* what) {
    skip();
    if (pos_ >= s_.size() || s_[pos_] == '#')
      throw InputError(name_, pos_, std::string("truncated: expected ") + what);
    const std::size_t at = pos_;
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(s_.data() + pos_, s_.data() + s_.size(), v);
    if (ec != std::errc() || (end < s_.data() + s_.size() && !is_space(*end) && *end != '#'))
      throw InputError(name_, at, std::string("expected ") + what + " (an unsigned integer)");
    pos_ = static_cast<std::size_t>(end - s_.data());
    return v;
  }
  // Offset of the first '#' comment from here, or the end if there is none; throws if
  // anything but blanks comes first.
  std::size_t trailer() {
    skip();
    if (pos_ < s_.size() && s_[pos_] != '#')
      throw InputError(name_, pos_, "expected the '#' trailer after the last task");
    return pos_;
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
  void skip() {
    while (pos_ < s_.size() && is_space(s_[pos_])) ++pos_;
  }
  std::string_view s_;
  const std::string& name_;
  std::size_t pos_ = 0;
};

std::optional<std::uint64_t> cp_length(std::string_view trailer) {
  const std::size_t at = trailer.find("CP Length");
  if (at == std::string_view::npos) return std::nullopt;
  const std::size_t colon = trailer.find(':', at);
  if (colon == std::string_view::npos) return std::nullopt;
  std::size_t p = colon + 1;
  while (p < trailer.size() && (trailer[p] == ' ' || trailer[p] == '\t')) ++p;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(trailer.data() + p, trailer.data() + trailer.size(), v);
  if (ec != std::errc() || end == trailer.data() + p) return std::nullopt;
  return v;
}

std::string basename(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

StgGraph parse_stg(std::string_view text, const std::string& name, std::uint64_t unit_ns,
                   std::uint64_t edge_bytes) {
  Tokens tok(text, name);
  const std::size_t n_at = tok.offset();
  const std::uint64_t n_real = tok.number("the task count");
  if (n_real > kMaxTasks || n_real + 2 > text.size() / 2 + 2)
    throw InputError(name, n_at, "task count " + std::to_string(n_real) + " is implausible for the file size");
  const std::uint64_t n = n_real + 2;  // with the dummy entry and exit tasks
  std::vector<std::uint64_t> cost(n);
  std::vector<std::vector<TaskId>> preds(n);
  std::uint64_t edges = 0;
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::size_t at = tok.offset();
    const std::uint64_t id = tok.number("a task number");
    if (id != i) throw InputError(name, at, "expected task number " + std::to_string(i) + ", got " + std::to_string(id));
    cost[i] = tok.number("a processing time");
    if (cost[i] > (std::uint64_t{1} << 40) / std::max<std::uint64_t>(unit_ns, 1))
      throw InputError(name, at, "processing time too large");
    const std::size_t np_at = tok.offset();
    const std::uint64_t np = tok.number("a predecessor count");
    if (np > i) throw InputError(name, np_at, "task " + std::to_string(i) + " cannot have " +
                                                  std::to_string(np) + " predecessors");
    edges += np;
    if (edges > kMaxEdges)
      throw InputError(name, np_at, "expected at most " + std::to_string(kMaxEdges) +
                                        " precedence edges in all, found more");
    for (std::uint64_t j = 0; j < np; ++j) {
      const std::size_t p_at = tok.offset();
      const std::uint64_t p = tok.number("a predecessor number");
      if (p >= i)
        throw InputError(name, p_at, "expected a predecessor numbered below " + std::to_string(i) +
                                         ", got " + std::to_string(p));
      preds[i].push_back(static_cast<TaskId>(p));
    }
  }
  const std::size_t trailer_at = tok.trailer();

  StgGraph out;
  out.cp_length = cp_length(text.substr(trailer_at));
  out.trace.header.scene = std::string("stg:").append(basename(name));
  out.trace.header.engine = "stg";
  out.trace.header.tgraph_version = TGRAPH_VERSION;
  StepGraph& g = out.trace.steps.emplace_back();
  const KindId real = g.intern_kind("stg_task");
  const KindId dummy = g.intern_kind("stg_dummy");
  // One datum per edge, written by the predecessor, read by the successor.
  std::vector<std::vector<Access>> acc(n);
  for (std::uint64_t i = 0; i < n; ++i) g.objects.push_back({"stg" + std::to_string(i)});
  for (std::uint64_t i = 0; i < n; ++i)
    for (TaskId p : preds[i]) {
      const auto d = static_cast<DatumId>(g.data.size());
      g.data.push_back({"e" + std::to_string(p) + "_" + std::to_string(i), p, edge_bytes});
      acc[p].push_back({d, AccessMode::W});
      acc[i].push_back({d, AccessMode::R});
    }
  for (std::uint64_t i = 0; i < n; ++i) {
    const bool is_dummy = i == 0 || i == n - 1;
    g.add_task(is_dummy ? dummy : real, static_cast<ObjectId>(i), acc[i], cost[i] * unit_ns, i + 1);
  }
  g.derive_edges();
  return out;
}

StgGraph read_stg(const std::string& path, std::uint64_t unit_ns, std::uint64_t edge_bytes) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_stg(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path,
                   unit_ns, edge_bytes);
}

std::string stg_import_report(const StgGraph& stg, const std::string& input,
                              const std::string& output, std::uint64_t unit_ns, bool json) {
  const StepGraph& g = stg.trace.steps.at(0);
  if (json) {
    nlohmann::json j = {{"input", input},
                        {"output", output},
                        {"tasks", g.tasks.size()},
                        {"edges", g.edges.size()},
                        {"unit_ns", unit_ns}};
    j["cp_length"] = optional_json(stg.cp_length);
    return j.dump() + "\n";
  }
  std::string out = "imported " + input + ": " + std::to_string(g.tasks.size()) + " tasks, " +
                    std::to_string(g.edges.size()) + " edges";
  if (stg.cp_length)
    out += ", stated critical path " + std::to_string(*stg.cp_length) +
           " units = " + std::to_string(*stg.cp_length * unit_ns) + " ns";
  return out + "\nwrote " + output + "\n";
}

std::string import_stg(const std::string& input, const std::string& output,
                       std::uint64_t unit_ns, std::uint64_t edge_bytes, bool json) {
  const StgGraph stg = read_stg(input, unit_ns, edge_bytes);
  write_trace(output, stg.trace);
  return stg_import_report(stg, input, output, unit_ns, json);
}

}  // namespace tgraph
