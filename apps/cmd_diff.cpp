// SPDX-License-Identifier: MIT
// `tgraph diff T.tgt --steps A B [--assignment A.tga] [--json]`: the structural difference of
// two steps by stable task key, with the contacts that caused it.
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/diff.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace tgraph::app {
namespace {

struct DiffOptions {
  std::string trace, assignment;
  std::vector<std::size_t> steps;
  bool json = false;
};

void run_diff(const DiffOptions& o) {
  const Trace trace = load_trace(o.trace);
  if (o.steps.size() != 2) throw UsageError("--steps: expected two step indices A B");
  for (std::size_t s : o.steps)
    if (s >= trace.steps.size())
      throw UsageError("--steps " + std::to_string(s) + ": trace " + o.trace + " has " +
                       std::to_string(trace.steps.size()) + " steps");
  const std::size_t a = o.steps[0], b = o.steps[1];
  StepDiff d = diff_steps(trace.steps[a], trace.steps[b]);
  if (!o.assignment.empty()) {
    const TraceAssignment as = partition::load_assignment(o.assignment, trace, o.trace);
    add_processor_changes(d, trace.steps[a], as.steps[a], trace.steps[b], as.steps[b]);
  }
  if (o.json)
    std::cout << step_diff_json(d, a, b) << std::endl;
  else
    std::fputs(step_diff_text(d, a, b).c_str(), stdout);
}

}  // namespace

void add_diff(CLI::App& app) {
  auto o = std::make_shared<DiffOptions>();
  auto* cmd = app.add_subcommand("diff", "Structural difference of two steps by stable task key");
  cmd->add_option("trace", o->trace, "Trace file (.tgt)")->required();
  cmd->add_option("--steps", o->steps, "The two steps A B (0-based)")->required()->expected(2);
  cmd->add_option("--assignment,-a", o->assignment,
                  "Assignment file (.tga): also list tasks whose processor changed");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run_diff(*o); });
}

}  // namespace tgraph::app
