// SPDX-License-Identifier: MIT
// Work-stealing baseline (oneTBB): the same dataflow graph executed by dependency counting,
// loops unrolled on the fly, no affinity from step to step (the paper's Cilk-like baseline).
//
// Instance (v, i) = task v in loop iteration i. Its count is the number of instances it
// waits for: iteration 0 (or outside loops): intra-step predecessors (a predecessor in
// another loop counts once, for that loop's end); iteration i > 0: same-iteration
// predecessors + loop-carried predecessors + the break of iteration i - 1 (the gate) +
// (v, i - 1) itself. A completed instance decrements its successors and spawns those that
// reach zero.
//
// Pinning (ExecOptions::pin): as oneTBB's users pin, through a task_scheduler_observer on the
// executor's arena: a thread entering the arena binds itself to its arena slot's core (the
// rule of every policy, pinning.hpp), once for as long as it keeps that slot.
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>
#include <oneapi/tbb/task_scheduler_observer.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <vector>

#include "common.hpp"
#include "pinning.hpp"
#include "planned_executor.hpp"
#include "sync.hpp"
#include "tgraph/replay/executor.hpp"
#include "tsan.hpp"
#include "worksteal_task.hpp"

namespace tgraph::replay {
namespace {

struct Block {
  std::atomic<std::uint32_t> remaining{0};  // body instances of this iteration not finished
  std::atomic<int> decision{-1};            // -1 unknown, 0 continue, 1 stop
  std::unique_ptr<std::atomic<std::uint32_t>[]> count;
};

struct LoopState {
  TaskId first = 0, last = 0;
  std::vector<std::atomic<Block*>> table;  // iteration -> block
  std::vector<std::uint32_t> init_next;    // counts of iterations > 0, by body index
  std::vector<TaskId> after;               // tasks outside the loop depending on its body
};

struct WsPlan {
  std::size_t n = 0;
  detail::Csr succ, succ_carried;
  std::vector<std::uint32_t> init0;  // non-loop tasks and iteration 0 of loop tasks
  std::vector<LoopState> loops;
  std::unique_ptr<std::atomic<std::uint32_t>[]> count0;  // non-loop tasks
};

/// Binds each thread that enters the arena to its slot's core (or, without pinning, undoes
/// a binding an earlier pinned executor left on oneTBB's shared worker threads).
class PinningObserver final : public tbb::task_scheduler_observer {
 public:
  PinningObserver(tbb::task_arena& arena, bool pin, std::uint32_t threads)
      : tbb::task_scheduler_observer(arena), pin_(pin), threads_(threads) {
    // oneTBB orders what was written before observe(true) before any entry, inside libtbb,
    // which ThreadSanitizer does not see: the annotation makes that order visible to it.
    TGRAPH_TSAN_RELEASE(this);
    observe(true);
  }
  ~PinningObserver() override {
    // observe(false) waits for the entries in progress (inside libtbb): after it, this
    // object may go.
    observe(false);
    TGRAPH_TSAN_ACQUIRE(this);
  }
  void on_scheduler_entry(bool /*worker*/) override {
    TGRAPH_TSAN_ACQUIRE(this);
    const int idx = tbb::this_task_arena::current_thread_index();
    detail::bind_current_thread(pin_, static_cast<std::uint32_t>(idx < 0 ? 0 : idx) % threads_);
    TGRAPH_TSAN_RELEASE(this);
  }

 private:
  bool pin_;
  std::uint32_t threads_;
};

class WorkstealExecutor final : public detail::PlannedExecutor<WsPlan> {
 public:
  explicit WorkstealExecutor(const ExecOptions& o)
      : PlannedExecutor(Policy::kWorksteal, o),
        control_(tbb::global_control::max_allowed_parallelism, o.threads),
        arena_(static_cast<int>(o.threads)),
        pinning_(arena_, o.pin, o.threads),
        counters_(o.threads) {}

 private:
  std::unique_ptr<WsPlan> build_plan(const ExecGraph& x) override {
    const StepGraph& g = x.graph;
    auto plan = std::make_unique<WsPlan>();
    const auto n = g.tasks.size();
    plan->n = n;
    plan->succ = detail::build_csr(n, g.edges, false);
    plan->succ_carried = detail::build_csr(n, g.carried_edges, false);
    const detail::Csr pred = detail::build_csr(n, g.edges, true);
    const detail::Csr pred_carried = detail::build_csr(n, g.carried_edges, true);
    plan->init0.assign(n, 0);
    plan->loops = std::vector<LoopState>(g.loops.size());
    for (LoopId l = 0; l < g.loops.size(); ++l) {
      LoopState& ls = plan->loops[l];
      ls.first = g.loops[l].first;
      ls.last = g.loops[l].last;
      const std::uint32_t cap = g.loops[l].max_iterations != 0
                                    ? std::min(g.loops[l].max_iterations, detail::kIterationCap)
                                    : detail::kIterationCap;
      ls.table = std::vector<std::atomic<Block*>>(cap + 2);
      ls.init_next.assign(ls.last - ls.first, 0);
    }
    std::vector<std::vector<bool>> after_seen(g.loops.size());
    for (TaskId v = 0; v < n; ++v) {
      const LoopId lv = g.tasks[v].loop;
      std::vector<LoopId> counted_loops;
      std::uint32_t c0 = 0, cn = 0;
      for (auto i = pred.begin[v]; i < pred.begin[v + 1]; ++i) {
        const TaskId u = pred.ids[i];
        const LoopId lu = g.tasks[u].loop;
        if (lu == kNoLoop) {
          ++c0;
        } else if (lu == lv) {
          ++c0;
          ++cn;
        } else if (std::find(counted_loops.begin(), counted_loops.end(), lu) ==
                   counted_loops.end()) {
          counted_loops.push_back(lu);
          ++c0;
          plan->loops[lu].after.push_back(v);
        }
      }
      plan->init0[v] = c0;
      if (lv != kNoLoop) {
        cn += pred_carried.size(v) + 2;  // carried + gate + previous instance of itself
        plan->loops[lv].init_next[v - plan->loops[lv].first] = cn;
      }
    }
    plan->count0 = std::make_unique<std::atomic<std::uint32_t>[]>(n);
    return plan;
  }

  Block* new_block(LoopState& ls, bool first) {
    auto* b = new Block;
    const std::size_t size = ls.last - ls.first;
    b->count = std::make_unique<std::atomic<std::uint32_t>[]>(size);
    // relaxed: the block is published afterwards by a release store of its table entry (or
    // before any spawn, which TBB orders), so these initial values are seen by all users.
    for (std::size_t j = 0; j < size; ++j)
      b->count[j].store(first ? step_.plan->init0[ls.first + j] : ls.init_next[j],
                        std::memory_order_relaxed);
    b->remaining.store(static_cast<std::uint32_t>(size), std::memory_order_relaxed);
    return b;
  }

  void spawn(TaskId t, std::uint32_t it) {
    TGRAPH_TSAN_RELEASE(&spawn_token_);  // TBB's hand-off to the thread running the task
    tg_->run(detail::SpawnedInstance{&WorkstealExecutor::trampoline, this, t, it});
  }

  static void trampoline(void* self, TaskId t, std::uint32_t it) {
    auto* ex = static_cast<WorkstealExecutor*>(self);
    TGRAPH_TSAN_ACQUIRE(&ex->spawn_token_);
    ex->run_instance(t, it);
    TGRAPH_TSAN_RELEASE(&ex->join_token_);  // TBB's task_group::wait()
  }

  // acq_rel: the last decrement acquires every earlier decrementer's writes (their tasks'
  // data) and the spawned task runs after it.
  void dec(std::atomic<std::uint32_t>& c, TaskId t, std::uint32_t it, ThreadCounters& tc) {
    ++tc.signals;
    if (c.fetch_sub(1, std::memory_order_acq_rel) == 1) spawn(t, it);
  }

  // A dependency of task s on an instance outside its loop (or s outside loops) is met.
  void release_first(TaskId s, ThreadCounters& tc) {
    const LoopId ls = step_.exec->graph.tasks[s].loop;
    if (ls == kNoLoop) {
      dec(step_.plan->count0[s], s, 0, tc);
    } else {
      LoopState& st = step_.plan->loops[ls];
      // acquire: the block was published with release before any instance could see it.
      Block* b = st.table[0].load(std::memory_order_acquire);
      dec(b->count[s - st.first], s, 0, tc);
    }
  }

  void run_instance(TaskId t, std::uint32_t it) {
    const int idx = tbb::this_task_arena::current_thread_index();
    const auto thread = static_cast<std::uint32_t>(idx < 0 ? 0 : idx) % options().threads;
    ThreadCounters& tc = counters_[thread];
    const ExecGraph& x = *step_.exec;
    const bool observe = !observers().empty() && detail::sampled(it, observe_stride());
    if (observe) detail::notify_begin(observers(), thread, t, it);
    step_.workload->run(TaskRun{&x, t, x.origin[t], it, thread});
    if (observe) detail::notify_end(observers(), thread, t, it);
    ++tc.tasks;
    const LoopId l = x.graph.tasks[t].loop;
    const WsPlan& p = *step_.plan;
    if (l == kNoLoop) {
      for (auto i = p.succ.begin[t]; i < p.succ.begin[t + 1]; ++i) release_first(p.succ.ids[i], tc);
      return;
    }
    LoopState& ls = step_.plan->loops[l];
    // acquire: blocks are published with release before the instances that use them run.
    Block* cur = ls.table[it].load(std::memory_order_acquire);
    Block* next = ls.table[it + 1].load(std::memory_order_acquire);
    for (auto i = p.succ.begin[t]; i < p.succ.begin[t + 1]; ++i) {
      const TaskId s = p.succ.ids[i];
      if (x.graph.tasks[s].loop == l) dec(cur->count[s - ls.first], s, it, tc);
    }
    for (auto i = p.succ_carried.begin[t]; i < p.succ_carried.begin[t + 1]; ++i) {
      const TaskId s = p.succ_carried.ids[i];
      dec(next->count[s - ls.first], s, it + 1, tc);
    }
    dec(next->count[t - ls.first], t, it + 1, tc);
    if (t + 1 == ls.last) {
      const bool stop = detail::leave_loop(x, l, it, *step_.workload);
      // relaxed: published by the release of the remaining-count decrement below.
      cur->decision.store(stop ? 1 : 0, std::memory_order_relaxed);
      if (stop) {
        // relaxed: read by the main thread after task_group::wait().
        iterations_[l] = it + 1;
      } else {
        // release: instances of iteration it + 1 acquire the table entry.
        ls.table[it + 2].store(new_block(ls, false), std::memory_order_release);
        for (TaskId v = ls.first; v < ls.last; ++v) dec(next->count[v - ls.first], v, it + 1, tc);
      }
    }
    // acq_rel: the last finisher of the iteration acquires every instance's release, the
    // break's included, so the relaxed load of the decision after it reads the final value.
    if (cur->remaining.fetch_sub(1, std::memory_order_acq_rel) == 1 &&
        cur->decision.load(std::memory_order_relaxed) == 1) {
      for (TaskId s : ls.after) release_first(s, tc);
    }
  }

  void run(WsPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override {
    const StepGraph& g = x.graph;
    if (fresh) detail::touch_all(g, w);  // no affinity: touched by the calling thread
    if (options().pin) main_binding_.save_once();  // the calling thread takes slot 0's core
    step_ = {&plan, &x, &w};
    iterations_.assign(g.loops.size(), 0);
    counters_.reset();
    for (TaskId t = 0; t < plan.n; ++t)
      plan.count0[t].store(plan.init0[t], std::memory_order_relaxed);  // relaxed: before any spawn
    for (LoopState& ls : plan.loops) {
      ls.table[0].store(new_block(ls, true), std::memory_order_relaxed);  // relaxed: before spawns
      ls.table[1].store(new_block(ls, false),
                        std::memory_order_relaxed);  // (task_group::run releases)
    }
    std::exception_ptr error;
    arena_.execute([&] {
      tbb::task_group tg;
      tg_ = &tg;
      for (TaskId t = 0; t < plan.n; ++t)
        if (plan.init0[t] == 0) spawn(t, 0);
      try {
        tg.wait();
      } catch (...) {
        error = std::current_exception();
      }
      TGRAPH_TSAN_ACQUIRE(&join_token_);
    });
    for (LoopState& ls : plan.loops)
      for (auto& e : ls.table) {
        Block* b = e.load(std::memory_order_relaxed);  // relaxed: all tasks finished
        if (!b) break;
        delete b;
        e.store(nullptr, std::memory_order_relaxed);  // relaxed: no task runs now
      }
    counters_.copy_to(stats);
    stats.loop_iterations = iterations_;
    if (error) std::rethrow_exception(error);
  }

  detail::MainThreadBinding main_binding_;  // restored after the observer is gone
  tbb::global_control control_;
  tbb::task_arena arena_;
  PinningObserver pinning_;
  detail::ThreadSlots counters_;
  detail::StepContext<WsPlan> step_;
  tbb::task_group* tg_ = nullptr;
  std::vector<std::uint32_t> iterations_;
  char spawn_token_ = 0;  // TSan: address standing for TBB's spawn hand-off
  char join_token_ = 0;
};

}  // namespace

std::unique_ptr<Executor> make_worksteal_executor(const ExecOptions& o) {
  return std::make_unique<WorkstealExecutor>(o);
}

}  // namespace tgraph::replay
