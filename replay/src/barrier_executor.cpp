// SPDX-License-Identifier: MIT
// Barrier baseline (the paper's first attempt): parallel phases (OpenMP `omp for`, static
// schedule) with barriers between them. BarrierRule::kOmpFor (default): as an OpenMP user
// writes a CG solver, one `omp for` per vector operation (a run of consecutive tasks of one
// kind in program order, cut where a task depends on the run) with a static schedule, so
// that the i-th object of every operation stays on one thread, and `nowait` wherever no task
// before the next barrier depends on a task of another thread since the last one (an
// operation that reads only its own objects' results of the previous one). The dot products'
// writers are one `omp for` whose reducer (the `reduction(+:)` combine) follows a barrier.
// BarrierRule::kLevel: one phase per dependency level of the step's dataflow graph within
// each loop region, a barrier after each. BarrierRule::kOperation (the paper's): the
// operations of kOmpFor with a barrier after each. Either way CW writers write the
// lowering's temporaries and a reducer phase adds them after the writers. Each thread runs
// the block of a phase that OpenMP's static schedule gives it (computed here, the same for
// every OpenMP runtime), then passes the phase's barrier if it has one.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <vector>

#include "common.hpp"
#include "omp_region.hpp"
#include "pinning.hpp"
#include "planned_executor.hpp"
#include "sync.hpp"
#include "tgraph/replay/executor.hpp"
#include "tsan.hpp"

namespace tgraph::replay {
namespace {

struct Phase {
  std::vector<TaskId> tasks;
  LoopId loop_end = kNoLoop;  // the phase ending a loop body: decide after it
  std::uint32_t jump = 0;     // first phase of that body
  bool barrier = true;        // a barrier after it (false: `nowait`)
};

struct BarrierPlan {
  std::vector<Phase> phases;
};

/// First index of thread `p`'s block of an `omp for schedule(static)` of `n` iterations on
/// `k` threads (the first n % k threads take one more); block p is [begin(p), begin(p + 1)).
std::size_t static_begin(std::size_t n, std::size_t k, std::size_t p) {
  const std::size_t q = n / k, r = n % k;
  return p * q + std::min(p, r);
}

/// The thread whose static block holds iteration i of n.
std::uint32_t static_thread(std::size_t i, std::size_t n, std::size_t k) {
  const std::size_t q = n / k, r = n % k;
  if (i < r * (q + 1)) return static_cast<std::uint32_t>(i / (q + 1));
  return static_cast<std::uint32_t>(r + (i - r * (q + 1)) / q);
}

class BarrierExecutor final : public detail::PlannedExecutor<BarrierPlan> {
 public:
  explicit BarrierExecutor(const ExecOptions& o)
      : PlannedExecutor(Policy::kBarrier, o), counters_(o.threads) {}

 private:
  std::unique_ptr<BarrierPlan> build_plan(const ExecGraph& x) override {
    switch (options().barrier.rule) {
      case BarrierRule::kOmpFor:
        return drop_barriers(x, build_by_operation(x));
      case BarrierRule::kLevel:
        return build_by_level(x);
      case BarrierRule::kOperation:
        return build_by_operation(x);
    }
    return build_by_operation(x);
  }

  // `nowait`: keeps the barrier before a phase only where one of its tasks depends on a task
  // that another thread ran since the last barrier (static blocks: the thread of each task
  // is known). The phase ending a loop body keeps its barrier (every thread reads the
  // decision after it; the next iteration's tasks then depend on nothing unsynchronised),
  // and so does the last phase.
  std::unique_ptr<BarrierPlan> drop_barriers(const ExecGraph& x, std::unique_ptr<BarrierPlan> plan) {
    const StepGraph& g = x.graph;
    const auto n = static_cast<TaskId>(g.tasks.size());
    const std::size_t k = options().threads;
    const detail::Csr pred = detail::build_csr(n, g.edges, true);
    constexpr std::uint32_t kNever = UINT32_MAX;
    std::vector<std::uint32_t> thread(n, 0), segment(n, kNever);
    std::uint32_t seg = 0;
    auto& phases = plan->phases;
    for (std::size_t ph = 0; ph < phases.size(); ++ph) {
      Phase& phase = phases[ph];
      const std::size_t size = phase.tasks.size();
      for (std::size_t i = 0; i < size; ++i) thread[phase.tasks[i]] = static_thread(i, size, k);
      bool cross = false;
      for (TaskId t : phase.tasks)
        for (auto i = pred.begin[t]; i < pred.begin[t + 1] && !cross; ++i)
          cross = segment[pred.ids[i]] == seg && thread[pred.ids[i]] != thread[t];
      if (cross && ph > 0) {
        phases[ph - 1].barrier = true;
        ++seg;
      }
      for (TaskId t : phase.tasks) segment[t] = seg;
      phase.barrier = phase.loop_end != kNoLoop || ph + 1 == phases.size();
      if (phase.barrier) ++seg;
    }
    return plan;
  }

  // Phases by dependency level. The tasks split into loop regions (runs of tasks of one loop
  // body, or outside loops, in program order), which follow each other with a barrier; in a
  // region, a task's level is 1 + the highest level of its predecessors in the region (0
  // without), and each level is one phase, its tasks in program order. Edges from earlier
  // regions are ordered by the region boundary, loop-carried edges by the barrier ending
  // each iteration. A loop's conditional break joins the body's last level, after which the
  // decision is read. The CW writers of one datum have no edges among each other (per-writer
  // temporaries) and share a phase when nothing else separates them; the reducer that adds
  // them is one level later.
  std::unique_ptr<BarrierPlan> build_by_level(const ExecGraph& x) {
    const StepGraph& g = x.graph;
    auto plan = std::make_unique<BarrierPlan>();
    const auto n = static_cast<TaskId>(g.tasks.size());
    const detail::Csr pred = detail::build_csr(n, g.edges, true);
    std::vector<std::uint32_t> level(n, 0);
    for (TaskId first = 0; first < n;) {
      const LoopId region = g.tasks[first].loop;
      TaskId end = first + 1;
      while (end < n && g.tasks[end].loop == region &&
             !(region != kNoLoop && g.loops[region].first == end))
        ++end;
      std::uint32_t top = 0;
      for (TaskId t = first; t < end; ++t) {
        for (auto i = pred.begin[t]; i < pred.begin[t + 1]; ++i)
          if (const TaskId p = pred.ids[i]; p >= first && p < t)
            level[t] = std::max(level[t], level[p] + 1);
        top = std::max(top, level[t]);
      }
      if (region != kNoLoop) level[end - 1] = top;  // the break ends the body's last phase
      const auto base = static_cast<std::uint32_t>(plan->phases.size());
      plan->phases.resize(base + top + 1);
      for (TaskId t = first; t < end; ++t) plan->phases[base + level[t]].tasks.push_back(t);
      if (region != kNoLoop) {
        plan->phases.back().loop_end = region;
        plan->phases.back().jump = base;
      }
      first = end;
    }
    return plan;
  }

  // Phases: runs of consecutive tasks of one kind in program order, cut where a task depends
  // on a task of the current phase. Reducers (CW groups lowered per writer) do not cut the
  // run they follow: they gather in a reduction phase that runs right after it, as an
  // OpenMP user writes a parallel loop with a reduction (the loop, then the combine).
  std::unique_ptr<BarrierPlan> build_by_operation(const ExecGraph& x) {
    const StepGraph& g = x.graph;
    auto plan = std::make_unique<BarrierPlan>();
    const auto n = static_cast<TaskId>(g.tasks.size());
    const detail::Csr pred = detail::build_csr(n, g.edges, true);
    constexpr std::uint32_t kNone = UINT32_MAX, kPending = UINT32_MAX - 1;
    std::vector<std::uint32_t> phase_of(n, kNone);
    auto& phases = plan->phases;
    Phase reducers;  // pending reduction phase, emitted after the current phase
    LoopId region = kNoLoop;
    std::uint32_t body_first_phase = 0;
    bool open = false;
    auto flush_reducers = [&] {
      if (reducers.tasks.empty()) return;
      for (TaskId r : reducers.tasks) phase_of[r] = static_cast<std::uint32_t>(phases.size());
      phases.push_back(std::move(reducers));
      reducers = Phase{};
    };
    auto close = [&] {
      open = false;
      flush_reducers();
    };
    auto depends_on = [&](TaskId t, std::uint32_t phase) {
      for (auto i = pred.begin[t]; i < pred.begin[t + 1]; ++i)
        if (phase_of[pred.ids[i]] == phase) return true;
      return false;
    };
    for (TaskId t = 0; t < n; ++t) {
      const Task& task = g.tasks[t];
      const bool region_change =
          task.loop != region || (task.loop != kNoLoop && g.loops[task.loop].first == t);
      if (region_change) {
        close();
        region = task.loop;
        if (region != kNoLoop) body_first_phase = static_cast<std::uint32_t>(phases.size());
      }
      const bool is_break = task.loop != kNoLoop && t + 1 == g.loops[task.loop].last;
      if (x.origin[t] == kNoTask && !is_break) {
        if (depends_on(t, kPending)) close();  // after the reducers it needs
        reducers.tasks.push_back(t);
        phase_of[t] = kPending;
        continue;
      }
      bool cut = !open || is_break || g.tasks[phases.back().tasks.front()].kind != task.kind ||
                 depends_on(t, kPending);
      if (!cut) cut = depends_on(t, static_cast<std::uint32_t>(phases.size() - 1));
      if (cut) {
        close();
        phases.emplace_back();
        open = true;
      }
      phases.back().tasks.push_back(t);
      phase_of[t] = static_cast<std::uint32_t>(phases.size() - 1);
      if (is_break) {
        phases.back().loop_end = task.loop;
        phases.back().jump = body_first_phase;
        open = false;
      }
    }
    close();
    return plan;
  }

  void run(BarrierPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override {
    const StepGraph& g = x.graph;
    const auto k = static_cast<int>(options().threads);
    if (options().pin) main_binding_.save_once();
    counters_.reset();
    std::vector<std::uint32_t> iterations(g.loops.size(), 0);
    // Decision of iteration i of a loop lives in slot i % 2: a fast thread may write the
    // next iteration's decision while a slow one still reads this one's.
    std::vector<std::array<int, 2>> decision(g.loops.size(), {0, 0});
    std::atomic<bool> abort{false};
    std::exception_ptr error;
    std::mutex error_mutex;
    const bool observe = !observers().empty();
    const std::uint32_t stride = observe_stride();
    const bool pin = options().pin;
    std::vector<std::uint8_t> is_break(g.tasks.size(), 0);
    for (const Loop& l : g.loops) is_break[l.last - 1] = 1;

    char token = 0;  // TSan: libgomp's fork, barriers and join, seen as release/acquire
    const auto region = TGRAPH_OMP_REGION {  // omp_region.hpp
      TGRAPH_TSAN_ACQUIRE(&detail::region_token);
      TGRAPH_TSAN_ACQUIRE(&token);
      const auto thread = static_cast<std::uint32_t>(omp_get_thread_num());
      detail::bind_current_thread(pin, thread);  // once: libgomp keeps its team's threads
      ThreadCounters& tc = counters_[thread];
      if (fresh) {
#pragma omp for schedule(static) nowait
        for (DatumId d = 0; d < g.data.size(); ++d)
          if (w.needs_touch(d)) w.first_touch(d);
        TGRAPH_TSAN_RELEASE(&token);
#pragma omp barrier
        TGRAPH_TSAN_ACQUIRE(&token);
      }
      std::size_t ph = 0;
      std::uint32_t iter = 0;
      while (ph < plan.phases.size()) {
        const Phase& phase = plan.phases[ph];
        // This thread's block of the phase under a static schedule (`omp for
        // schedule(static) nowait`, computed here so that every runtime splits it alike).
        const std::size_t size = phase.tasks.size();
        const std::size_t end = static_begin(size, static_cast<std::size_t>(k), thread + 1);
        for (std::size_t i = static_begin(size, static_cast<std::size_t>(k), thread); i < end;
             ++i) {
          const TaskId t = phase.tasks[i];
          // relaxed: a hint to skip work once a task failed; the barriers order the rest.
          const bool aborted = abort.load(std::memory_order_relaxed);
          if (!aborted) {
            try {
              if (observe && detail::sampled(iter, stride)) detail::notify_begin(observers(), thread, t, iter);
              w.run(TaskRun{&x, t, x.origin[t], iter, thread});
              if (observe && detail::sampled(iter, stride)) detail::notify_end(observers(), thread, t, iter);
              ++tc.tasks;
            } catch (...) {
              std::lock_guard<std::mutex> lock(error_mutex);
              if (!error) error = std::current_exception();
              abort.store(true, std::memory_order_relaxed);  // relaxed: see above
            }
          }
          if (is_break[t]) {
            const LoopId l = g.tasks[t].loop;
            bool stop = true;
            if (!abort.load(std::memory_order_relaxed)) {  // relaxed: see above
              try {
                stop = detail::leave_loop(x, l, iter, w);
              } catch (...) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
                abort.store(true, std::memory_order_relaxed);  // relaxed: see above
              }
            }
            decision[l][iter % 2] = stop ? 1 : 0;
            if (stop) iterations[l] = iter + 1;
          }
        }
        if (phase.barrier) {
          TGRAPH_TSAN_RELEASE(&token);
#pragma omp barrier
          TGRAPH_TSAN_ACQUIRE(&token);
          ++tc.waits;
        }
        // After the barrier the phase's writes (and the loop decision) are visible to all.
        if (phase.loop_end != kNoLoop && decision[phase.loop_end][iter % 2] == 0) {
          ++iter;
          ph = phase.jump;
        } else {
          if (phase.loop_end != kNoLoop) iter = 0;
          ++ph;
        }
      }
      TGRAPH_TSAN_RELEASE(&token);
    };
    TGRAPH_TSAN_RELEASE(&token);
    detail::omp_parallel(k, region);
    TGRAPH_TSAN_ACQUIRE(&token);
    counters_.copy_to(stats);
    stats.loop_iterations = iterations;
    if (error) std::rethrow_exception(error);
  }

  detail::ThreadSlots counters_;
  detail::MainThreadBinding main_binding_;
};

}  // namespace

std::unique_ptr<Executor> make_barrier_executor(const ExecOptions& o) {
  return std::make_unique<BarrierExecutor>(o);
}

}  // namespace tgraph::replay
