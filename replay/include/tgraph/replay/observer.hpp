// SPDX-License-Identifier: MIT
// Observers of an executor: timelines, per-thread counters and locality are computed here,
// from read-only callbacks, never by code inside the executors' hot loops.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/lowering.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/timeline.hpp"

namespace tgraph::replay {

/// Nanoseconds on the steady clock (the time base of every callback).
std::int64_t now_ns();

/// One CPU relaxation hint (a spinning thread's pause between two polls).
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

/// Receives the events of an executor. Callbacks for different `thread` values may come
/// concurrently; callbacks for one thread come in order from that thread. Instances of one
/// task (its loop iterations) never overlap.
///
///   TimelineObserver timeline;
///   executor->add_observer(timeline);
///   executor->run_step(g, &a, workload);
///   write_file_atomic("r.json", timeline_json(timeline.timeline()));
class Observer {
 public:
  virtual ~Observer() = default;
  /// Before the first task of a step (calling thread). `exec` stays valid until on_step_end.
  virtual void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t t_ns) {
    (void)exec, (void)threads, (void)t_ns;
  }
  /// A task instance starts on `thread`.
  virtual void on_begin(std::uint32_t thread, TaskId task, std::uint32_t iteration,
                        std::int64_t t_ns) {
    (void)thread, (void)task, (void)iteration, (void)t_ns;
  }
  /// A task instance ends on `thread`.
  virtual void on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
                      std::int64_t t_ns) {
    (void)thread, (void)task, (void)iteration, (void)t_ns;
  }
  /// `thread` waited from t0 to t1 before running `task` (only waits that did not succeed at
  /// once are reported; `parked` = it slept in the kernel).
  virtual void on_wait(std::uint32_t thread, TaskId task, std::int64_t t0, std::int64_t t1,
                       bool parked) {
    (void)thread, (void)task, (void)t0, (void)t1, (void)parked;
  }
  /// After the last task of the step, once every thread is done (calling thread).
  virtual void on_step_end(std::int64_t t_ns) { (void)t_ns; }
};

/// Per-thread busy / waiting / idle time of each step.
class StatsObserver : public Observer {
 public:
  /// Per-thread totals of one step.
  struct Thread {
    std::int64_t busy_ns = 0;
    std::int64_t wait_ns = 0;
    std::int64_t idle_ns = 0;  ///< step wall time minus busy and waiting
    std::uint64_t tasks = 0;
  };
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t t_ns) override;
  void on_begin(std::uint32_t thread, TaskId task, std::uint32_t iteration,
                std::int64_t t_ns) override;
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
              std::int64_t t_ns) override;
  void on_wait(std::uint32_t thread, TaskId task, std::int64_t t0, std::int64_t t1,
               bool parked) override;
  void on_step_end(std::int64_t t_ns) override;
  /// The last step's per-thread figures.
  const std::vector<Thread>& threads() const { return last_; }

 private:
  struct alignas(64) Slot {
    std::int64_t begin = 0;
    Thread t;
  };
  std::vector<Slot> slots_;
  std::vector<Thread> last_;
  std::int64_t step_begin_ = 0;
};

/// Data locality of each step, from which thread ran each task instance:
/// remote bytes = bytes a task reads (RAW edge) that a different thread wrote in this step;
/// migrated bytes = bytes of data whose owner thread (the thread of its first writer in the
/// step) differs from the previous step's.
class LocalityObserver : public Observer {
 public:
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t t_ns) override;
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
              std::int64_t t_ns) override;
  void on_step_end(std::int64_t t_ns) override;
  /// Remote bytes of the last step.
  std::uint64_t remote_bytes() const { return remote_; }
  /// Migrated bytes of the last step (0 for the first step).
  std::uint64_t migrated_bytes() const { return migrated_; }

 private:
  const ExecGraph* exec_ = nullptr;
  std::vector<std::vector<std::uint16_t>> where_;  // exec task -> thread per iteration
  std::vector<std::uint32_t> prev_owner_;          // original datum -> owner thread, last step
  std::uint64_t remote_ = 0;
  std::uint64_t migrated_ = 0;
};

/// Records every task instance (thread, start, end, the thread's CPU time in the body) and
/// every blocking wait, and per step the executed graph (interned: steps of one structure
/// share it), each task's cost, the loops' iterations and the execution's wall time: what
/// tgraph::explain needs to find the critical path and attribute the lost time.
class TimelineObserver : public Observer {
 public:
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t t_ns) override;
  void on_begin(std::uint32_t thread, TaskId task, std::uint32_t iteration,
                std::int64_t t_ns) override;
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
              std::int64_t t_ns) override;
  void on_wait(std::uint32_t thread, TaskId task, std::int64_t t0, std::int64_t t1,
               bool parked) override;
  void on_step_end(std::int64_t t_ns) override;

  /// What was recorded so far: every task instance (its kind named from the step it ran in),
  /// step by step, sorted by start time within a step, and every blocking wait.
  /// timeline_json() writes it; viz draws it and converts it to Chrome / Perfetto trace
  /// events (what a replay writes when asked for its timeline).
  const Timeline& timeline() const { return timeline_; }
  /// Keeps at most this many steps (older steps are not recorded); default unlimited.
  void set_max_steps(std::uint32_t n) { max_steps_ = n; }
  /// Also reads each thread's CPU time around every body (CLOCK_THREAD_CPUTIME_ID, a system
  /// call of 250-290 ns on the 2-core VM: TimelineTask::cpu_ns, which tells interruptions
  /// apart). Off by default: the first read lies inside every observer's span of the body
  /// (on_begin's time is taken before the observers run), so it lengthens the bodies that
  /// the other observers of the pass measure.
  void set_cpu_time(bool on) { cpu_time_ = on; }
  /// The serial phases of the calling thread before the last recorded step's execution
  /// (record, partitioning waited, preparation) and the part of them the sequential program
  /// runs too (host work): TimelineStep's fields, which the executor cannot see.
  void set_serial(std::int64_t record_ns, std::int64_t partition_ns, std::int64_t prepare_ns,
                  std::int64_t host_ns = 0);
  /// The sequential cost of one execution of each task of the step graph (by original
  /// task) for the last recorded step, replacing the executed graph's costs (a live run's
  /// costs measured in its sequential pass).
  void set_sequential_costs(const std::vector<std::int64_t>& cost_by_origin);

 private:
  // What a thread records in its callbacks (no string: the kind is named at step end).
  struct Instance {
    TaskId task = 0;
    std::uint32_t iteration = 0;
    std::int64_t start_ns = 0, end_ns = 0;
    std::int64_t cpu_ns = -1;
  };
  std::vector<std::vector<Instance>> per_thread_;
  std::vector<std::vector<TimelineWait>> waits_per_thread_;
  std::vector<std::int64_t> open_;  // start and CPU time of the running task, per thread (8 apart)
  Timeline timeline_;
  bool cpu_time_ = false;
  const ExecGraph* exec_ = nullptr;
  std::int64_t step_begin_ = 0;
  std::uint32_t max_steps_ = 0xffffffffu;
  bool recording_ = false;
};

}  // namespace tgraph::replay
