// SPDX-License-Identifier: MIT
// `tgraph diff T.tgt --steps A B [--assignment A.tga] [--json]`: the structural difference of
// two steps by stable task key, with the contacts that caused it (libgraph's diff_steps).
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/diff.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace tgraph::app {

void add_diff(CLI::App& app) {
  auto o = std::make_shared<Args>();
  auto steps = std::make_shared<std::vector<std::size_t>>();
  auto* cmd = app.add_subcommand("diff", "Structural difference of two steps by stable task key");
  cmd->add_option("trace", o->input, "Trace file (.tgt)")->required();
  cmd->add_option("steps", *steps, "The two steps A B (0-based)")->required()->expected(2);
  cmd->add_option("--assignment,-a", o->assignment,
                  "Assignment file (.tga): also list tasks whose processor changed");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o, steps] {
    const Trace trace = read_trace(o->input);
    if (steps->size() != 2) throw UsageError("--steps: expected two step indices A B");
    const std::size_t a = (*steps)[0], b = (*steps)[1];
    const StepGraph &ga = step_at(trace, a, o->input, "steps"),
                    &gb = step_at(trace, b, o->input, "steps");
    StepDiff d = diff_steps(ga, gb);
    if (!o->assignment.empty()) {
      const TraceAssignment as = partition::load_assignment(o->assignment, trace, o->input);
      add_processor_changes(d, ga, as.steps[a], gb, as.steps[b]);
    }
    std::cout << (o->json ? step_diff_json(d, a, b) + "\n" : step_diff_text(d, a, b));
  });
}

}  // namespace tgraph::app
