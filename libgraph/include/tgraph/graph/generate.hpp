// SPDX-License-Identifier: MIT
// Synthetic steps of any size (`tgraph generate`): Task Bench's shapes and a scaled solver
// step, with data accesses and costs, deterministic from a seed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"

namespace tgraph {

/// The shape of a generated step. The first four are Task Bench's (Slaughter et al., SC'20):
/// `width` columns over as many layers as the task count needs; the task of column i in
/// layer t writes cell i of buffer t mod 2 and reads cells of buffer (t - 1) mod 2.
enum class Pattern : std::uint8_t {
  kTrivial = 0,  ///< no data: independent tasks
  kStencil = 1,  ///< reads cells i - 1, i, i + 1 (1-D stencil)
  kRandom = 2,   ///< reads cell i and `degree` cells drawn uniformly over the width
  kTree = 3,     ///< reads cells i and i xor 2^((t - 1) mod log2 width) (fft butterfly)
  kDomain = 4,   ///< a solver step: per object a force task, then a CG loop with dot products
};

/// "trivial", "stencil", "random", "tree" or "domain".
std::string_view to_string(Pattern p);
/// The pattern named `name`, or nothing.
std::optional<Pattern> pattern_from_string(std::string_view name);

/// What generate_step() builds.
struct GenerateOptions {
  std::uint64_t tasks = 1000;  ///< tasks of the step (exactly, except domain: about)
  Pattern pattern = Pattern::kStencil;
  std::uint64_t width = 0;     ///< columns (0: tasks / 16, at least 1); domain: ignored
  std::uint32_t degree = 2;    ///< random: cells read besides the task's own
  std::uint64_t seed = 1;      ///< costs and random reads derive from it, nothing else
  std::uint64_t cost_ns = 1000;  ///< mean task cost; each cost is uniform in [1/2, 3/2] of it
  std::uint64_t datum_bytes = 4096;  ///< size of every cell (domain: vectors)
  std::uint32_t iterations = 25;     ///< domain: CG iterations of the loop
};

/// One generated step (edges not derived). Step `step` of a trace differs from step 0 only
/// in its costs (the structure is the same). Throws OptionError when the options are out of
/// range (no tasks, more than 2^32 - 2 tasks or data, width above tasks).
StepGraph generate_step(const GenerateOptions& options, std::uint32_t step = 0);

/// `steps` generated steps (edges derived) with a header naming the pattern.
///
///   Trace t = generate_trace({.tasks = 1'000'000, .pattern = Pattern::kRandom}, 1);
///   write_trace("random.tgt", t);
Trace generate_trace(const GenerateOptions& options, std::uint32_t steps);

/// A step of `chains` independent chains and the assignment of chain p to processor p:
/// `chains` x `per_chain` tasks of `cost_ns` each in round robin (task i rewrites datum
/// i mod chains, "chain <p>" of 64 bytes, after the chain's previous task), edges derived.
/// What a runtime's own time per task is measured on (`tgraph calibrate`, `tgraph-mpi
/// calibrate`): every wait is on the task's own processor.
struct ChainsStep {
  StepGraph graph;
  Assignment assignment;
};
ChainsStep chains_step(std::uint32_t chains, std::uint32_t per_chain, std::uint64_t cost_ns);

/// What generate_file() wrote: the first step's sizes (every step has them).
struct GeneratedFile {
  std::string output;
  GenerateOptions options;
  std::size_t steps = 0, tasks = 0, data = 0, accesses = 0;
  std::size_t edges = 0;  ///< edges and loop-carried edges
  double seconds = 0.0;   ///< generating and writing
};

/// generate_trace() written to `output` (`tgraph generate`), timed.
GeneratedFile generate_file(const GenerateOptions& options, std::uint32_t steps,
                            const std::string& output);
/// One JSON object (trace, pattern, steps, tasks, data, accesses, edges, seed, seconds).
std::string generated_json(const GeneratedFile& f);
/// "wrote T.tgt: S step(s) of N tasks, ..." with a newline.
std::string generated_text(const GeneratedFile& f);

}  // namespace tgraph
