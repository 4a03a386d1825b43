// SPDX-License-Identifier: MIT
// Regression tests for the crashes the fuzz targets found (the inputs themselves are in
// tests/fuzz/corpus/<target>/crash_*, replayed by the fuzz.<target>.corpus tests).
#include <gtest/gtest.h>

#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/model/cost_model.hpp"
#if defined(TGRAPH_HAVE_VIZ)
#include "tgraph/viz/report.hpp"
#include "tgraph/viz/timeline.hpp"
#endif

namespace tgraph {
namespace {

std::string calibration_error(const std::string& text) {
  try {
    model::parse_calibration(text, "c.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// calibration_fuzz, crash_number_overflow: nlohmann::json throws out_of_range (not
// parse_error) for a number beyond double range, which escaped the reader.
TEST(CalibrationReader, RefusesANumberBeyondDoubleRange) {
  EXPECT_EQ(calibration_error("1e400[1]"),
            "c.json: expected numbers within double range, found a number overflow parsing "
            "'1e400'");
  EXPECT_EQ(calibration_error("{\"sync_latency_ns\": 1e400, \"per_byte_ns\": 1}"),
            "c.json: expected numbers within double range, found a number overflow parsing "
            "'1e400'");
  EXPECT_EQ(calibration_error("{\"sync_latency_ns\": -1e999}"),
            "c.json: expected numbers within double range, found a number overflow parsing "
            "'-1e999'");
}

#if defined(TGRAPH_HAVE_VIZ)
// The replay timeline reader (`tgraph export --format chrome`, `replay --chrome`,
// `timeline`, `report`): parse_timeline, then the Chrome trace made from it.
std::string timeline_error(const std::string& tasks) {
  try {
    viz::chrome_trace(parse_timeline("{\"tasks\": [" + tasks + "]}", "t.json"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
#endif

std::string event(const std::string& step, const std::string& thread, const std::string& task,
                  const std::string& start, const std::string& end) {
  return "{\"step\": " + step + ", \"thread\": " + thread + ", \"task\": " + task +
         ", \"origin\": null, \"iteration\": 0, \"start_ns\": " + start + ", \"end_ns\": " + end +
         "}";
}

// timeline_fuzz, crash_float_step.json: a float step converted to an unsigned integer
// (undefined behaviour under UBSan); crash_huge_task_id.json: a task id of 4e8 allocated
// 4e8 labels; crash_duration_overflow.json: end - start overflowed.
#if defined(TGRAPH_HAVE_VIZ)
TEST(TimelineReader, RefusesFieldsOutOfRangeInsteadOfConvertingThem) {
  const auto refused = [](const std::string& err, const char* field) {
    return err.rfind("t.json: tasks[", 0) == 0 && err.find(field) != std::string::npos;
  };
  EXPECT_PRED2(refused, timeline_error(event("3.3e38", "0", "0", "0", "1")), "step");
  EXPECT_PRED2(refused, timeline_error(event("0", "4294967295", "0", "0", "1")), "thread");
  EXPECT_PRED2(refused,
               timeline_error(event("0", "0", "0", "-9223372036854775808", "9223372036854775807")),
               "start_ns");
  EXPECT_PRED2(refused, timeline_error(event("0", "0", "0", "5", "4")), "end_ns");
  // A large task id is a number, not a size: nothing is allocated by it.
  EXPECT_EQ(timeline_error(event("0", "0", "0", "0", "1") + "," +
                           event("0", "0", "400000000", "0", "1")),
            "");
}
#endif

#if defined(TGRAPH_HAVE_VIZ)
// The viz readers of the same files (`tgraph timeline`, `tgraph report --replay/--compare`),
// found by reading them after they were merged (the timeline target now feeds them too):
// crash_viz_step_max.json, a step of 2^32-1, sized step_offsets() to 0 entries and wrote
// past it (`tgraph timeline` exited 139); crash_viz_span_overflow.json, steps whose ends add
// up beyond 2^63-1 ns, overflowed the offsets; crash_viz_thread_max.json, a thread of 2^32-1,
// wrapped the thread count to 0; crash_report_float_k.json, a float "k" converted to an
// unsigned integer.
std::string viz_timeline_error(const std::string& tasks) {
  try {
    parse_timeline("{\"tasks\": [" + tasks + "]}", "t.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(VizTimelineReader, BoundsStepsThreadsAndTimesBeforeSizingAnythingByThem) {
  EXPECT_EQ(viz_timeline_error(event("4294967295", "0", "0", "0", "1")),
            "t.json: tasks[0]: \"step\": 4294967295 (expected < 1, the number of events)");
  EXPECT_EQ(viz_timeline_error(event("0", "4294967295", "0", "0", "1")),
            "t.json: tasks[0]: \"thread\": 4294967295 (expected < 4096)");
  EXPECT_EQ(viz_timeline_error(event("0", "0", "0", "0", "9223372036854775807") + "," +
                               event("1", "0", "1", "0", "1")),
            "t.json: the steps laid end to end or the tasks' total time exceed 2^63-1 ns "
            "(expected a replay timeline's nanoseconds)");
  EXPECT_EQ(viz_timeline_error(event("0", "0", "0", "0", "9223372036854775807") + "," +
                               event("0", "1", "1", "0", "9223372036854775807")),
            "t.json: the steps laid end to end or the tasks' total time exceed 2^63-1 ns "
            "(expected a replay timeline's nanoseconds)");
  // The largest times that fit are kept and laid end to end.
  const Timeline t =
      parse_timeline("{\"tasks\": [" + event("0", "0", "0", "0", "4611686018427387904") + "," +
                              event("1", "1", "1", "0", "4611686018427387903") + "]}",
                          "t.json");
  EXPECT_EQ(t.threads, 2u);
  EXPECT_EQ(t.step_offsets(), (std::vector<std::int64_t>{0, 4611686018427387904}));
}

TEST(ReportReader, RefusesCountsThatAreNotUnsignedIntegers) {
  const auto compare_error = [](const std::string& k) {
    viz::ReportContent c;
    try {
      viz::add_compare_json(c,
                            "{\"rows\": [{\"method\": \"owner\", \"k\": " + k +
                                ", \"partition_ms\": 1, \"imbalance\": 1, \"cut_bytes\": 8, "
                                "\"migrated_tasks\": 0, \"predicted_speedup\": 1.5}]}",
                            "c.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return c.rows.size() == 1 && c.rows[0].k == 2 ? std::string() : std::string("wrong row");
  };
  EXPECT_EQ(compare_error("2"), "");
  EXPECT_EQ(compare_error("3.3e38"),
            "c.json: rows[0]: \"k\" must be an unsigned integer <= 4294967295");
  EXPECT_EQ(compare_error("4294967296"),
            "c.json: rows[0]: \"k\" must be an unsigned integer <= 4294967295");
  EXPECT_EQ(compare_error("-1"),
            "c.json: rows[0]: \"k\" must be an unsigned integer <= 4294967295");
  viz::ReportContent c;
  EXPECT_THROW(viz::add_replay_json(c,
                                    "{\"policy\": \"worksteal\", \"threads\": 2, "
                                    "\"wall_ns\": 1, \"sequential_wall_ns\": 2, "
                                    "\"speedup\": 2, \"efficiency\": 1, \"signals\": 1e300}",
                                    "r.json"),
               InputError);
}
#endif

}  // namespace
}  // namespace tgraph
