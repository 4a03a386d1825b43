// SPDX-License-Identifier: MIT
// ThreadSanitizer still sees the executors' own races under tgraph's suppressions
// (tests/replay/tsan_suppressions.cpp, which names the runtime libraries only): a race
// planted in an executor's state (tsan_planted_race, a process of its own) is reported,
// naming the executor, and the same steps run apart are clean. Built in the tsan preset only.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace {

struct Outcome {
  int status = -1;  ///< exit status (-1: did not exit)
  std::string output;
};

/// Runs the planted-race program with `args`, its stderr with its stdout.
Outcome run_planted(const std::string& args) {
  const std::string command = std::string(TGRAPH_PLANTED_RACE) + " " + args + " 2>&1";
  Outcome o;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return o;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) o.output.append(buf.data(), n);
  const int raw = pclose(pipe);
  if (raw != -1 && WIFEXITED(raw)) o.status = WEXITSTATUS(raw);
  return o;
}

/// Whether a report's access lies in `file`: the first frame of one of its stacks that is
/// not in a system header (`    #0 ...` unless that is a standard library function inlined
/// into the caller's code, such as a shared_ptr's test, at the caller's address). The race
/// an entry such as `race_top:BarrierExecutor::run` used to suppress.
bool top_frame_in(const std::string& output, const std::string& file) {
  for (std::size_t at = output.find("    #0 "); at != std::string::npos;
       at = output.find("    #0 ", at + 1)) {
    // The stack's frames, #0, #1, ..., one per line; the first outside /usr/include.
    for (std::size_t line = at; line != std::string::npos && output.compare(line, 5, "    #") == 0;) {
      const std::size_t end = output.find('\n', line);
      const std::string frame = output.substr(line, end == std::string::npos ? end : end - line);
      if (frame.find("/usr/include/") == std::string::npos) {
        if (frame.find(file) != std::string::npos) return true;
        break;
      }
      line = end == std::string::npos ? end : end + 1;
    }
  }
  return false;
}

class PlantedRace : public ::testing::TestWithParam<const char*> {};

TEST_P(PlantedRace, IsReportedNamingTheExecutor) {
  const std::string policy = GetParam();
  const Outcome o = run_planted(policy + " together");
  // TSan's exit status after a report (its exitcode option, 66 by default).
  EXPECT_EQ(o.status, 66) << o.output;
  EXPECT_NE(o.output.find("WARNING: ThreadSanitizer: data race"), std::string::npos) << o.output;
  // Which of the planted races TSan meets first depends on the interleaving: the executor's
  // own run (barrier_executor.cpp), its step context (executor.cpp) or its thread slots
  // (common.hpp, inlined into the executor's run). Each is the executor's state: an access
  // in replay/src/, on a stack through the policy's executor.
  const std::string file = policy == "barrier" ? "barrier_executor.cpp" : "omp_tasks_executor.cpp";
  EXPECT_TRUE(top_frame_in(o.output, "replay/src/")) << o.output;
  EXPECT_NE(o.output.find("replay/src/" + file), std::string::npos) << o.output;
}

TEST_P(PlantedRace, RunApartTheSameStepsAreClean) {
  const Outcome o = run_planted(std::string(GetParam()) + " apart");
  EXPECT_EQ(o.status, 0) << o.output;
  EXPECT_EQ(o.output.find("ThreadSanitizer"), std::string::npos) << o.output;
}

INSTANTIATE_TEST_SUITE_P(Policies, PlantedRace, ::testing::Values("barrier", "omp-tasks"),
                         [](const auto& info) {
                           return std::string(info.param) == "barrier" ? "barrier" : "omp_tasks";
                         });

}  // namespace
