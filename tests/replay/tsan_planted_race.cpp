// SPDX-License-Identifier: MIT
// A race planted in the OpenMP executors' own state: built (under ThreadSanitizer only) from
// the executors' own sources with TGRAPH_TSAN_PLANT_RACE, where every thread of the parallel
// region increments an executor member without synchronisation, and linked with the
// suppressions replay_test uses. TsanReport.FindsARacePlantedInAnExecutorsOwnState runs it and
// expects ThreadSanitizer to report the race: suppressions that named the executors' own
// functions hid exactly this. Usage: tsan_planted_race barrier|omp-tasks
#define TGRAPH_TSAN_PLANT_RACE 1
#define make_barrier_executor make_planted_barrier_executor
#define make_omp_tasks_executor make_planted_omp_tasks_executor
#include "barrier_executor.cpp"
#include "omp_tasks_executor.cpp"
#undef make_barrier_executor
#undef make_omp_tasks_executor

#include <cstdio>
#include <string>

#include "tgraph/replay/synthetic.hpp"

int main(int argc, char** argv) {
  namespace tr = tgraph::replay;
  const std::string which = argc > 1 ? argv[1] : "";
  tr::ExecOptions o;
  o.threads = 2;
  o.pin = false;
  std::unique_ptr<tr::Executor> ex;
  if (which == "barrier") ex = tr::make_planted_barrier_executor(o);
  if (which == "omp-tasks") ex = tr::make_planted_omp_tasks_executor(o);
  if (!ex) {
    std::fprintf(stderr, "usage: tsan_planted_race barrier|omp-tasks\n");
    return 2;
  }
  tgraph::StepGraph g;
  const tgraph::KindId k = g.intern_kind("work");
  for (int i = 0; i < 8; ++i) {
    g.objects.push_back({"o" + std::to_string(i)});
    g.data.push_back({"d" + std::to_string(i), static_cast<tgraph::ObjectId>(i), 64});
    g.add_task(k, static_cast<tgraph::ObjectId>(i),
               std::vector<tgraph::Access>{{static_cast<tgraph::DatumId>(i), tgraph::AccessMode::W}},
               20'000, static_cast<tgraph::StableKey>(i + 1));
  }
  g.derive_edges();
  tr::SyntheticWorkload w;
  w.set_step(g);
  for (int s = 0; s < 3; ++s) ex->run_step(g, nullptr, w);
  std::printf("ran %s\n", which.c_str());
  return 0;
}
