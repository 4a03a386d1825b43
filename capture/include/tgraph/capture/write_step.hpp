// SPDX-License-Identifier: MIT
// Writing a recorded step to a trace, refusing a step whose recording misused the API.
#pragma once

#include <string>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph::capture {

/// A step was recorded with API misuses (an unbalanced loop, a loop body that changed...):
/// its graph is not what the engine ran. A failure of the engine's code, not of an input
/// (the command line exits 1).
class MisuseError : public ErrorWithFields {
 public:
  using ErrorWithFields::ErrorWithFields;
};

/// The misuses of the step `rec` ended last, as one line: the first one (its call, problem,
/// loop, step and task count) and how many more; empty when there are none.
std::string step_misuse_line(const Recorder& rec);

/// Appends `g`, the step `rec` has just ended, to `writer`, unless the recorder saw API
/// misuses in it: then nothing is written and MisuseError names the first one (its
/// problem names the field `{allow_misuse}`). `allow_misuse`: write it anyway.
///
///   StepGraph g = rec.end_step();
///   capture::append_step(writer, rec, g);  // MisuseError: "end_step: the loop is still open..."
void append_step(TraceWriter& writer, const Recorder& rec, const StepGraph& g,
                 bool allow_misuse = false);

}  // namespace tgraph::capture
