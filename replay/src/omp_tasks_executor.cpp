// SPDX-License-Identifier: MIT
// OpenMP tasks with `depend` clauses as a peer policy: the lowered step submitted, in
// program order, by one thread of a parallel region (`omp single`) as OpenMP tasks, with
// one dependence object per exec datum and the recorded modes; the OpenMP runtime (GCC's
// libgomp here) derives the order from the clauses and places the tasks.
//
// Modes: R -> in, W -> out, RW -> inout. CW: under the default per-writer lowering (one CW
// writer per datum and group, later writers on temporaries of their own, then a reducer
// task with inout on the target and the temporaries) -> inout, which keeps the sum in
// program order (bit-identical to a sequential run of the same reduction order). With the
// reduce scope none (CW groups left with several writers) -> mutexinoutset, OpenMP 5.0's
// "any order, one at a time"; GCC 12's libgomp treats it as out (the writers serialise in
// program order), see docs/replay.md for the measured comparison. Task reductions
// (`task_reduction`/`in_reduction`) need the writers to add into the runtime's private copy,
// which opaque bodies cannot, and a taskgroup per CW group, which blocks the submitting
// thread: they are not used.
//
// Loops: a loop whose iteration count the workload knows (a replay) is unrolled at
// submission, with a `taskwait` after each iteration when OmpTasksOptions::iteration_wait
// (as an OpenMP program testing convergence must do; it also keeps libgomp's dependence
// lists short). Otherwise (live physics) one iteration is submitted, the submitting thread
// waits for it and reads the break task's decision. A loop task that writes none of its data
// with W or RW also has a private inout object so that its iterations never overlap.
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <vector>

#include "common.hpp"
#include "omp_region.hpp"
#include "pinning.hpp"
#include "planned_executor.hpp"
#include "sync.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tsan.hpp"

namespace tgraph::replay {
namespace {

/// Dependence list of one exec task: `ids[first ...]` holds its in, out, inout and
/// mutexinoutset objects, in that order.
struct TaskDeps {
  std::uint32_t first = 0;
  std::uint16_t in = 0, out = 0, inout = 0, mutex = 0;
};

struct OmpPlan {
  std::uint32_t objects = 0;  // exec data, then private objects of loop tasks
  std::vector<TaskDeps> deps;
  std::vector<std::uint32_t> ids;
  std::unique_ptr<char[]> object;  // the dependence objects (their addresses)
  /// Per loop, an object its break task writes (out or inout): `taskwait depend(in:)` on it
  /// waits for the break and what it depends on.
  std::vector<std::uint32_t> break_object;
};

/// What the break task of a loop iteration does after its body.
enum class Check : std::uint8_t {
  kNone = 0,      ///< not a break task
  kDecide = 1,    ///< evaluate the condition and store it (the submitter waits for it)
  kUnrolled = 2,  ///< unrolled: the condition must agree with the known count
};

class OmpTasksExecutor final : public detail::PlannedExecutor<OmpPlan> {
 public:
  explicit OmpTasksExecutor(const ExecOptions& o)
      : PlannedExecutor(Policy::kOmpTasks, o), counters_(o.threads) {
    // LLVM's libomp 14 (Debian 12) aborts in its dependence bookkeeping on `taskwait depend`
    // from GCC-built code ("Assertion failure at kmp_taskdeps.h(26): n >= 0", falling64 at 2
    // threads, docs/replay.md): refused rather than crash the process.
    if (o.omp_tasks.wait_depend && openmp_runtime() == "llvm")
      throw OptionError("omp_wait",
                        "depend aborts LLVM's OpenMP runtime from this build (libomp 14, "
                        "kmp_taskdeps.h assertion); use {omp_wait} all or {openmp_runtime} gnu");
  }

 private:
  std::unique_ptr<OmpPlan> build_plan(const ExecGraph& x) override {
    const StepGraph& g = x.graph;
    auto plan = std::make_unique<OmpPlan>();
    plan->objects = static_cast<std::uint32_t>(g.data.size());
    const auto n = static_cast<TaskId>(g.tasks.size());
    plan->deps.resize(n);
    const bool mutex_cw = x.scope != ReduceScope::kPerWriter && x.scope != ReduceScope::kPerThread;
    std::vector<Access> merged;
    std::vector<std::uint32_t> by_mode[4];
    for (TaskId t = 0; t < n; ++t) {
      // A datum listed twice by one task becomes one dependence (RW when the modes differ).
      merged.clear();
      for (const Access& a : g.accesses_of(t)) {
        auto m = std::find_if(merged.begin(), merged.end(),
                              [&](const Access& b) { return b.datum == a.datum; });
        if (m == merged.end())
          merged.push_back(a);
        else if (m->mode != a.mode)
          m->mode = AccessMode::RW;
      }
      for (auto& v : by_mode) v.clear();
      bool ordered = false;  // a W or RW access orders consecutive instances already
      for (const Access& a : merged) {
        switch (a.mode) {
          case AccessMode::R:
            by_mode[0].push_back(a.datum);
            break;
          case AccessMode::W:
            by_mode[1].push_back(a.datum);
            ordered = true;
            break;
          case AccessMode::RW:
            by_mode[2].push_back(a.datum);
            ordered = true;
            break;
          case AccessMode::CW:
            if (x.thread_temps != 0 && x.datum_origin[a.datum] != a.datum) {
              // Per-thread temporaries: the writers of a group run in any order, even at
              // once, each on its thread's temporary; `in` on the block's first orders them
              // after the previous reducer and before the next (inout), as RW would not.
              by_mode[0].push_back(a.datum);
            } else {
              by_mode[mutex_cw ? 3 : 2].push_back(a.datum);
              ordered |= !mutex_cw;
            }
            break;
        }
      }
      if (g.tasks[t].loop != kNoLoop && !ordered) by_mode[2].push_back(plan->objects++);
      TaskDeps& d = plan->deps[t];
      d.first = static_cast<std::uint32_t>(plan->ids.size());
      d.in = static_cast<std::uint16_t>(by_mode[0].size());
      d.out = static_cast<std::uint16_t>(by_mode[1].size());
      d.inout = static_cast<std::uint16_t>(by_mode[2].size());
      d.mutex = static_cast<std::uint16_t>(by_mode[3].size());
      for (const auto& v : by_mode) plan->ids.insert(plan->ids.end(), v.begin(), v.end());
    }
    for (const Loop& l : g.loops) {
      // A break task writes an object: its own W/RW data, or its private inout object.
      const TaskDeps& d = plan->deps[l.last - 1];
      plan->break_object.push_back(plan->ids[d.first + d.in]);
    }
    plan->object = std::make_unique<char[]>(std::max<std::uint32_t>(1, plan->objects));
    return plan;
  }

  void fail(std::exception_ptr e) {
    std::lock_guard lock(error_mutex_);
    if (!error_) error_ = std::move(e);
    // relaxed: a hint for the tasks still to run; error_ itself is read under the mutex.
    failed_.store(true, std::memory_order_relaxed);
  }

  /// Body of one task instance (runs on whichever thread of the team libgomp picks).
  void run_instance(TaskId t, std::uint32_t it, Check check, std::uint32_t count) {
    const OmpPlan& p = *step_.plan;
    const TaskDeps& d = p.deps[t];
    const std::uint32_t nd = d.in + d.out + d.inout + d.mutex;
    // TSan: libgomp's dependence release is not instrumented; each object stands for it.
    TGRAPH_TSAN_ACQUIRE(&submit_token_);
    for (std::uint32_t i = 0; i < nd; ++i) TGRAPH_TSAN_ACQUIRE(&p.object[p.ids[d.first + i]]);
    const auto thread = static_cast<std::uint32_t>(omp_get_thread_num());
    // relaxed: only skips work after a failure; the error itself is passed under a mutex.
    if (!failed_.load(std::memory_order_relaxed)) {
      try {
        const ExecGraph& x = *step_.exec;
        const bool observe = !observers().empty() && detail::sampled(it, observe_stride());
        if (observe) detail::notify_begin(observers(), thread, t, it);
        step_.workload->run(TaskRun{&x, t, x.origin[t], it, thread});
        if (observe) detail::notify_end(observers(), thread, t, it);
        ++counters_[thread].tasks;
        const LoopId l = x.graph.tasks[t].loop;
        if (check == Check::kDecide)
          decision_ = detail::leave_loop(x, l, it, *step_.workload) ? 1 : 0;
        else if (check == Check::kUnrolled)
          detail::check_unrolled(x, l, it, count, *step_.workload);
      } catch (...) {
        fail(std::current_exception());
      }
    }
    for (std::uint32_t i = 0; i < nd; ++i) TGRAPH_TSAN_RELEASE(&p.object[p.ids[d.first + i]]);
    TGRAPH_TSAN_RELEASE(&join_token_);
  }

  /// Creates the OpenMP task of instance (t, it), its dependences from the plan.
  void submit(TaskId t, std::uint32_t it, Check check, std::uint32_t count) {
    const OmpPlan& p = *step_.plan;
    const TaskDeps& d = p.deps[t];
    char* obj = p.object.get();
    const std::uint32_t* in = p.ids.data() + d.first;
    const std::uint32_t* out = in + d.in;
    const std::uint32_t* inout = out + d.out;
    const std::uint32_t* mutex = inout + d.inout;
    const int n_in = d.in, n_out = d.out, n_inout = d.inout, n_mutex = d.mutex;
    (void)obj;  // GCC 12 warns it unused when only iterator clauses read it
    TGRAPH_TSAN_RELEASE(&submit_token_);
#pragma omp task firstprivate(t, it, check, count)                                   \
    depend(iterator(i = 0 : n_in), in : obj[in[i]])                                   \
    depend(iterator(i = 0 : n_out), out : obj[out[i]])                                \
    depend(iterator(i = 0 : n_inout), inout : obj[inout[i]])                          \
    depend(iterator(i = 0 : n_mutex), mutexinoutset : obj[mutex[i]])
    run_instance(t, it, check, count);
  }

  /// After submitting an iteration of loop `l`: waits for its break task (OpenMP 5.0
  /// `taskwait depend`) or for every task submitted so far (`taskwait`).
  void wait_iteration(LoopId l) {
    if (options().omp_tasks.wait_depend) {
      char* obj = step_.plan->object.get() + step_.plan->break_object[l];
#pragma omp taskwait depend(in : obj[0])
      TGRAPH_TSAN_ACQUIRE(obj);  // the break task's release of its objects
    } else {
#pragma omp taskwait
      TGRAPH_TSAN_ACQUIRE(&join_token_);
    }
  }

  /// Submits the whole step from the `single` thread; returns early on failure.
  void submit_step(const ExecGraph& x, Workload& w) {
    const StepGraph& g = x.graph;
    detail::walk_step(
        g, [this] { return failed_.load(std::memory_order_relaxed); },  // relaxed: see fail()
        [this](TaskId t) { submit(t, 0, Check::kNone, 0); },
        [&](LoopId l) {
          const Loop& loop = g.loops[l];
          if (const std::optional<std::uint32_t> known = w.known_iterations(l)) {
            const std::uint32_t count = detail::unrolled_count(loop, *known);
            for (std::uint32_t it = 0; it < count; ++it) {
              for (TaskId u = loop.first; u < loop.last; ++u)
                submit(u, it, u + 1 == loop.last ? Check::kUnrolled : Check::kNone, count);
              if (options().omp_tasks.iteration_wait) {
                wait_iteration(l);
                if (failed_.load(std::memory_order_relaxed)) return;  // relaxed: see fail()
              }
            }
            iterations_[l] = count;
          } else {
            for (std::uint32_t it = 0;; ++it) {
              decision_ = -1;
              for (TaskId u = loop.first; u < loop.last; ++u)
                submit(u, it, u + 1 == loop.last ? Check::kDecide : Check::kNone, 0);
              wait_iteration(l);
              iterations_[l] = it + 1;
              if (decision_ != 0) break;  // leave, or the break task did not run (failure)
            }
          }
        });
  }

  void run(OmpPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override {
    const StepGraph& g = x.graph;
    if (fresh) detail::touch_all(g, w);  // no affinity: touched by the calling thread
    if (options().pin) main_binding_.save_once();
    step_ = {&plan, &x, &w};
    error_ = nullptr;
    failed_.store(false, std::memory_order_relaxed);  // relaxed: no task runs now
    iterations_.assign(g.loops.size(), 0);
    counters_.reset();
    const bool pin = options().pin;
    const auto region = TGRAPH_OMP_REGION {  // omp_region.hpp
      TGRAPH_TSAN_ACQUIRE(&detail::region_token);
      TGRAPH_TSAN_ACQUIRE(&submit_token_);
      // Once per thread and slot: the runtime keeps its team's threads from region to region.
      detail::bind_current_thread(pin, static_cast<std::uint32_t>(omp_get_thread_num()));
#pragma omp single
      {
        try {
          submit_step(x, w);
        } catch (...) {
          fail(std::current_exception());
        }
      }  // the implicit barrier waits for every task
      TGRAPH_TSAN_RELEASE(&join_token_);
    };
    TGRAPH_TSAN_RELEASE(&submit_token_);
    detail::omp_parallel(static_cast<int>(options().threads), region);
    TGRAPH_TSAN_ACQUIRE(&join_token_);
    stats.loop_iterations = iterations_;
    counters_.copy_to(stats);
    std::exception_ptr error;
    {
      std::lock_guard lock(error_mutex_);
      error = error_;
    }
    if (error) std::rethrow_exception(error);
  }

  detail::ThreadSlots counters_;
  detail::StepContext<OmpPlan> step_;
  std::vector<std::uint32_t> iterations_;
  int decision_ = -1;  // the live loop's break: 1 leave, 0 continue (read after taskwait)
  std::atomic<bool> failed_{false};
  std::mutex error_mutex_;
  std::exception_ptr error_;
  detail::MainThreadBinding main_binding_;
  char submit_token_ = 0;  // TSan: address standing for libgomp's task creation hand-off
  char join_token_ = 0;    // TSan: address standing for taskwait and the region's end
};

}  // namespace

std::unique_ptr<Executor> make_omp_tasks_executor(const ExecOptions& o) {
  return std::make_unique<OmpTasksExecutor>(o);
}

}  // namespace tgraph::replay
