// SPDX-License-Identifier: MIT
// `tgraph generate --tasks N --pattern P -o T.tgt`: a synthetic trace of any size
// (tgraph::generate_trace), for scaling studies of the graph core, partitioners and executors.
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/generate.hpp"

namespace tgraph::app {

void add_generate(CLI::App& app) {
  using enum Pattern;
  auto a = std::make_shared<Args>();
  auto o = std::make_shared<GenerateOptions>();
  auto* cmd = app.add_subcommand(
      "generate", "Write a synthetic trace: Task Bench's shapes or a solver step, of N tasks");
  cmd->add_option("--tasks", o->tasks, "Tasks per step")
      ->required()
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{4294967294}));
  add_enum(cmd, "--pattern", o->pattern, {kTrivial, kStencil, kRandom, kTree, kDomain},
           "trivial, stencil (1-D), random (degree cells over the width), tree (fft butterfly) "
           "or domain (a solver step with a CG loop); default stencil");
  cmd->add_option("--width", o->width, "Columns of the Task Bench shapes (default tasks / 16)");
  cmd->add_option("--degree", o->degree, "random: cells each task reads besides its own (2)")
      ->check(CLI::Range(0u, 64u));
  cmd->add_option("--iterations", o->iterations, "domain: CG iterations (25)")
      ->check(CLI::Range(1u, 100000u));
  cmd->add_option("--cost-ns", o->cost_ns, "Mean task cost in ns (1000; uniform in 1/2..3/2 of it)");
  cmd->add_option("--seed", o->seed, "Seed of the costs and random reads (1)");
  cmd->add_option("--steps", a->steps, "Steps (same structure, costs drawn per step; 1)")
      ->check(CLI::Range(1u, 100000u));
  cmd->add_option("-o,--output", a->output, "Trace file to write (.tgt)")->required();
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a, o] {
    const GeneratedFile f = generate_file(*o, a->steps, a->output);
    std::cout << (a->json ? generated_json(f) + "\n" : generated_text(f));
  });
}

}  // namespace tgraph::app
