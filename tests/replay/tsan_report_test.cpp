// SPDX-License-Identifier: MIT
// Under ThreadSanitizer: the suppressions (tsan_suppressions.cpp) name the uninstrumented
// runtime libraries only, so a race in an executor's own state is still reported. The race is
// planted in a separate process (tsan_planted_race.cpp) whose exit status and report are read.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace {

#if defined(__SANITIZE_THREAD__) && defined(TGRAPH_PLANTED_RACE_BIN)
/// Runs the planted-race program for `policy`; its exit status and stderr + stdout.
std::pair<int, std::string> run_planted(const std::string& policy) {
  const std::string cmd = std::string(TGRAPH_PLANTED_RACE_BIN) + " " + policy + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = fread(buf.data(), 1, buf.size(), p)) > 0;) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}
#endif

TEST(TsanReport, FindsARacePlantedInAnExecutorsOwnState) {
#if defined(__SANITIZE_THREAD__) && defined(TGRAPH_PLANTED_RACE_BIN)
  for (const char* policy : {"barrier", "omp-tasks"}) {
    const auto [code, out] = run_planted(policy);
    // The program ran to its end, and TSan's report (exit status 66, its default) names
    // the planted member in the executor's parallel region.
    EXPECT_NE(out.find(std::string("ran ") + policy), std::string::npos) << out;
    EXPECT_EQ(code, 66) << policy << ":\n" << out;
    EXPECT_NE(out.find("WARNING: ThreadSanitizer: data race"), std::string::npos) << out;
    EXPECT_NE(out.find(policy == std::string("barrier") ? "BarrierExecutor::run"
                                                        : "OmpTasksExecutor::run"),
              std::string::npos)
        << out;
  }
#else
  GTEST_SKIP() << "only under ThreadSanitizer (the tsan preset)";
#endif
}

}  // namespace
