// SPDX-License-Identifier: MIT
// `tgraph explain`'s pipeline: the input file told apart (a timeline, gzip or JSON, or a
// result with its timeline or its attribution), then explained or its attribution printed.
#include "tgraph/explain/command.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "tgraph/explain/explain.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/timeline.hpp"

namespace tgraph::explain {
namespace {

// A run's or replay's JSON without a timeline: its attribution, per step, as the table.
std::string attribution_only(const nlohmann::json& j, const ExplainCommand& a) {
  if (!j.contains("attribution") || !j["attribution"].is_object())
    throw InputError(a.input, std::nullopt,
                     "neither a timeline nor a result with \"attribution\" (expected tgraph "
                     "replay/run --json output or a --timeline file)");
  Explanation e;
  e.threads = j.value("threads", 0u);
  const auto read = [&](const nlohmann::json& o) {
    Attribution at;
    try {
      at.lost_ns = o.at("lost_ns").get<std::int64_t>();
      for (const std::string_view n : cause_names())
        cause(at.causes, n) = o.at("causes").at(std::string(n)).get<std::int64_t>();
    } catch (const nlohmann::json::exception&) {
      throw InputError(a.input, std::nullopt,
                       "\"attribution\" must hold lost_ns and causes {serial, ..., residual}");
    }
    return at;
  };
  e.attribution = read(j["attribution"]);
  if (j.contains("per_step") && j["per_step"].is_array()) {
    std::uint32_t index = 0;
    for (const auto& s : j["per_step"]) {
      const std::uint32_t step = s.value("step", index);
      ++index;
      if (a.step && step != *a.step) continue;
      if (!s.contains("attribution")) continue;
      StepExplanation x;
      x.step = step;
      x.threads = e.threads;
      x.attribution = read(s["attribution"]);
      // The attribution is of the observed pass, whose makespan the result does not give.
      x.makespan_ns = 0;
      x.work_ns = 0;
      e.steps.push_back(std::move(x));
    }
    if (a.step && e.steps.empty())
      throw InputError(a.input, std::nullopt, "no step " + std::to_string(*a.step));
  }
  if (a.json) {
    nlohmann::json out = nlohmann::json::parse(explanation_json(e));
    return out.dump() + "\n";
  }
  return explanation_text(e, a.input) +
         "(no timeline: record one with --timeline for the critical path and the what-ifs)\n";
}

}  // namespace

std::string explain_command(const ExplainCommand& c) {
  const std::string text = read_file_text(c.input);
  const bool gzip = text.size() >= 2 && static_cast<unsigned char>(text[0]) == 0x1f &&
                    static_cast<unsigned char>(text[1]) == 0x8b;
  std::string timeline_path = c.input;
  if (!gzip) {
    const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded())
      throw InputError(c.input, std::nullopt,
                       "not JSON (expected a timeline or a replay/run --json result)");
    if (j.is_object() && !j.contains("tasks")) {
      // A result: its timeline when it names one that exists, else its attribution.
      if (j.contains("timeline") && j["timeline"].is_string()) {
        std::filesystem::path p = j["timeline"].get<std::string>();
        if (p.is_relative()) p = std::filesystem::path(c.input).parent_path() / p;
        if (std::filesystem::exists(p)) timeline_path = p.string();
      }
      if (timeline_path == c.input) {
        return attribution_only(j, c);
      }
    }
  }
  const Timeline t =
      timeline_path == c.input ? parse_timeline(text, c.input) : read_timeline(timeline_path);
  ExplainOptions o;
  o.step = c.step;
  const Explanation e = explain_timeline(t, timeline_path, o);
  return c.json ? explanation_json(e) + "\n" : explanation_text(e, timeline_path);
}

}  // namespace tgraph::explain
