// SPDX-License-Identifier: MIT
// API misuse named: the recorder's list (call, loop, step, task count) and the trace writer
// that refuses a step recorded with misuses.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/capture/write_step.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph::capture {
namespace {

using M = AccessMode;

// One step: a task, then a CG-like loop on "cg.converged" of two tasks per iteration; `close`
// calls end_loop, `late_break` adds a conditional_break after it.
void loop_step(Recorder& rec, DatumId x, DatumId c, bool close, bool late_break) {
  const KindId k = rec.kind("k"), dot = rec.kind("dot");
  rec.begin_step();
  rec.task(k, kNoObject, {{x, M::W}}, [] {});
  const LoopId l = rec.begin_loop(c, 3);
  do {
    rec.task(dot, kNoObject, {{x, M::R}, {c, M::W}}, [] {});
    rec.task(dot, kNoObject, {{x, M::R}, {c, M::RW}}, [] {});
  } while (!rec.conditional_break(l, [] { return false; }));
  if (close) rec.end_loop(l);
  if (late_break) rec.conditional_break(l, [] { return true; });
}

TEST(Misuse, AMissingEndLoopIsNamedByCallLoopStepAndTaskCount) {
  Recorder rec(Mode::kCapture);
  const DatumId x = rec.datum("x", kNoObject, 8), c = rec.datum("cg.converged", kNoObject, 1);
  loop_step(rec, x, c, true, false);
  rec.end_step();
  EXPECT_EQ(rec.step_errors(), 0u);
  loop_step(rec, x, c, false, false);
  rec.end_step();
  ASSERT_EQ(rec.errors(), 1u);
  EXPECT_EQ(rec.step_errors(), 1u);
  ASSERT_EQ(rec.misuses().size(), 1u);
  const Misuse& m = rec.misuses()[0];
  EXPECT_EQ(m.call, Call::kEndStep);
  EXPECT_EQ(m.loop, "loop 0 on cg.converged");
  EXPECT_EQ(m.step, 1u);
  EXPECT_EQ(m.tasks, 4u);  // the task, the loop's two and its break
  EXPECT_EQ(to_string(m),
            "end_step: the loop is still open (missing end_loop) (loop 0 on cg.converged, step 1, "
            "after 4 tasks)");
}

TEST(Misuse, AConditionalBreakAfterEndLoopIsNamed) {
  Recorder rec(Mode::kDeferred);
  const DatumId x = rec.datum("x", kNoObject, 8), c = rec.datum("cg.converged", kNoObject, 1);
  loop_step(rec, x, c, true, true);
  rec.end_step_program();
  ASSERT_EQ(rec.misuses().size(), 1u);
  EXPECT_EQ(rec.misuses()[0].call, Call::kConditionalBreak);
  EXPECT_EQ(to_string(rec.misuses()[0]),
            "conditional_break: the loop was closed by end_loop (loop 0 on cg.converged, step 0, "
            "after 4 tasks)");
}

TEST(Misuse, ALoopBodyThatChangesNamesBothTasks) {
  Recorder rec(Mode::kCapture);
  const DatumId c = rec.datum("c", kNoObject, 1);
  const KindId a = rec.kind("a"), b = rec.kind("b");
  const ObjectId o = rec.object("tile(0,0)");
  rec.begin_step();
  const LoopId l = rec.begin_loop(c, 2);
  int it = 0;
  do {
    rec.task(it++ == 0 ? a : b, o, {{c, M::W}}, [] {});
  } while (!rec.conditional_break(l, [] { return false; }));
  rec.end_loop(l);
  rec.end_step();
  ASSERT_FALSE(rec.misuses().empty());
  EXPECT_EQ(rec.misuses()[0].problem,
            "iteration 1 issued b of tile(0,0) where the first iteration issued a of tile(0,0)");
  EXPECT_EQ(rec.misuses()[0].loop, "loop 0 on c");
}

TEST(Misuse, TheTraceWriterRefusesAStepWithMisusesUnlessAllowed) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("tgraph_misuse_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "t.tgt").string();
  Recorder rec(Mode::kCapture);
  const DatumId x = rec.datum("x", kNoObject, 8), c = rec.datum("cg.converged", kNoObject, 1);
  {
    TraceWriter w(path, TraceHeader{"s", "e", "m", "v"});
    loop_step(rec, x, c, true, false);
    append_step(w, rec, rec.end_step());
    loop_step(rec, x, c, false, false);
    const StepGraph bad = rec.end_step();
    try {
      append_step(w, rec, bad);
      FAIL() << "the step was written";
    } catch (const MisuseError& e) {
      EXPECT_EQ(std::string(e.what()),
                "end_step: the loop is still open (missing end_loop) (loop 0 on cg.converged, "
                "step 1, after 4 tasks); the step is not written (write it anyway with "
                "allow_misuse)");
      EXPECT_EQ(e.render([](const std::string& f) { return "--" + f; }).substr(0, 8), "end_step");
    }
    EXPECT_EQ(w.steps_written(), 1u);
    append_step(w, rec, bad, true);  // asked for
    EXPECT_EQ(w.steps_written(), 2u);
    w.close();
  }
  EXPECT_EQ(read_trace(path).steps.size(), 2u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tgraph::capture
