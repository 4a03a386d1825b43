// SPDX-License-Identifier: MIT
// StarPU as a peer policy: the lowered step submitted, in program order, as StarPU tasks with
// one data handle per datum and the recorded access modes; StarPU's implicit (sequential
// consistency) dependencies order them, its scheduler (default lws) places them.
//
// Modes: R -> STARPU_R, W -> STARPU_W, RW -> STARPU_RW; CW -> STARPU_RW | STARPU_COMMUTE
// where CW groups keep several writers per datum (reduce scope none), STARPU_RW under the
// default per-writer lowering (one writer per datum and group, then the in-order reducer).
// A loop whose iteration count the workload knows in advance (a replay) is unrolled at
// submission; otherwise (live physics) one iteration is submitted, the host waits for its
// break task and submits the next one or leaves, as StarPU applications do for CG.
// A loop task that writes none of its data with W or RW also accesses a private handle
// (STARPU_RW) so that its iterations run in order and never overlap (Observer's contract).
#include <exception>
#include <memory>

#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"

#if defined(TGRAPH_HAVE_STARPU)

#include <starpu.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "common.hpp"
#include "pinning.hpp"
#include "planned_executor.hpp"
#include "sync.hpp"
#include "tsan.hpp"
#include "tgraph/replay/starpu_modes.hpp"

namespace tgraph::replay {
namespace {

// One StarPU runtime per process: set while a StarPU executor exists.
std::atomic<bool> g_starpu_in_use{false};
// TSan: address standing for StarPU's hand-off of a submitted task to a worker (the codelet
// argument is read before the executor is known, hence not a member).
char g_submit_token = 0;

#if defined(__SANITIZE_THREAD__)
constexpr bool kTsan = true;
#else
constexpr bool kTsan = false;
#endif

struct StarpuPlan;

/// The plans whose handles are registered; the executor unregisters them before shutting
/// StarPU down (the base class destroys its plan cache after the derived destructor).
struct Registry {
  bool up = true;
  std::vector<StarpuPlan*> plans;
};

/// Handles of one exec graph and, per exec task, its buffers (handle index + mode).
struct StarpuPlan {
  std::shared_ptr<Registry> registry;
  std::vector<starpu_data_handle_t> handles;  // exec data, then private handles of loop tasks
  std::vector<std::uint32_t> begin;           // exec task -> first buffer (size n + 1)
  std::vector<std::uint32_t> buffer;          // handle index of each buffer
  std::vector<starpu_data_access_mode> mode;  // access mode of each buffer

  void release() {
    // Every task using them has finished (execute waits for all): nothing to wait for.
    for (starpu_data_handle_t h : handles) starpu_data_unregister(h);
    handles.clear();
  }
  ~StarpuPlan() {
    if (!registry || !registry->up) return;
    release();
    std::erase(registry->plans, this);
  }
};

/// What the break task of a loop iteration does after its body.
enum class Check : std::uint8_t {
  kNone = 0,      ///< not a break task
  kDecide = 1,    ///< evaluate the condition and store it (the host waits for it)
  kContinue = 2,  ///< unrolled: the condition must say "continue"
  kStop = 3,      ///< unrolled: the condition must say "stop"
};

class StarpuExecutor;

/// One submitted task instance (the codelet's argument).
struct Instance {
  StarpuExecutor* ex = nullptr;
  TaskId task = 0;
  std::uint32_t iteration = 0;
  Check check = Check::kNone;
  int decision = -1;  // kDecide: 1 leave, 0 continue (written by the task, read after the wait)
};

std::string scheduler_names() {
  std::string s;
  for (starpu_sched_policy** p = starpu_sched_get_predefined_policies(); p && *p; ++p) {
    if (!s.empty()) s += ", ";
    s += (*p)->policy_name;
  }
  return s;
}

bool known_scheduler(const std::string& name) {
  for (starpu_sched_policy** p = starpu_sched_get_predefined_policies(); p && *p; ++p)
    if (name == (*p)->policy_name) return true;
  return false;
}

/// Sets an environment variable for the lifetime of the object, then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

class StarpuExecutor final : public detail::PlannedExecutor<StarpuPlan> {
 public:
  explicit StarpuExecutor(const ExecOptions& o)
      : PlannedExecutor(Policy::kStarpu, o),
        registry_(std::make_shared<Registry>()),
        counters_(o.threads) {
    if (o.threads > STARPU_MAXCPUS)
      throw OptionError("threads",
                        "at most " + std::to_string(STARPU_MAXCPUS) +
                            " with {policy} starpu (this StarPU build's CPU workers, "
                            "STARPU_MAXCPUS); got " + std::to_string(o.threads));
    if (!known_scheduler(o.starpu.sched))
      throw OptionError("starpu_sched", "'" + o.starpu.sched +
                                            "' is not a StarPU scheduler; expected one of " +
                                            scheduler_names());
    if (g_starpu_in_use.exchange(true))
      throw UsageError(
          "StarPU: another StarPU executor is alive in this process (StarPU is one runtime per "
          "process); destroy it first");
    setenv("STARPU_SILENT", "1", 0);  // StarPU's banners would spoil a JSON report on stdout
    starpu_conf conf;
    cpu_only_conf(conf, o.threads);  // our flags win over STARPU_NCPU etc.
    conf.sched_policy_name = options().starpu.sched.c_str();
    // Pinning (ExecOptions::pin): the rule of every policy, worker i on slot i's PU (StarPU
    // names PUs by hwloc's logical index); the submitting thread shares slot 0's core (bound in
    // run()), so K workers and the submitter take K cores, as the calling thread of the other
    // policies is their thread 0. StarPU cannot run tasks on the submitting thread itself.
    const bool bind = o.pin && detail::pinned_pu_logical(0) >= 0;
    if (bind) {
      conf.use_explicit_workers_bindid = 1;
      for (std::uint32_t i = 0; i < o.threads; ++i)
        conf.workers_bindid[i] = static_cast<unsigned>(detail::pinned_pu_logical(i));
    }
    int rc = 0;
    {
      std::optional<ScopedEnv> nobind;
      if (!bind) nobind.emplace("STARPU_WORKERS_NOBIND", "1");
      rc = starpu_init(&conf);
    }
    if (rc != 0) {
      g_starpu_in_use.store(false);
      throw Error("StarPU: starpu_init failed (" + std::to_string(rc) + ")");
    }
    if (starpu_cpu_worker_get_count() != o.threads) {
      const unsigned got = starpu_cpu_worker_get_count();
      starpu_shutdown();
      g_starpu_in_use.store(false);
      throw OptionError("threads", std::to_string(o.threads) +
                                       " CPU workers for {policy} starpu, StarPU started " +
                                       std::to_string(got));
    }
    starpu_pause();  // idle workers poll; paused they sleep (between steps, baselines)
    starpu_codelet_init(&codelet_);
    codelet_.where = STARPU_CPU;
    codelet_.cpu_funcs[0] = &StarpuExecutor::body;
    codelet_.nbuffers = STARPU_VARIABLE_NBUFFERS;
    codelet_.name = "tgraph";
  }

  ~StarpuExecutor() override {
    for (StarpuPlan* p : registry_->plans) p->release();
    registry_->plans.clear();
    registry_->up = false;
    starpu_resume();
    starpu_shutdown();
    g_starpu_in_use.store(false);
  }

 private:
  std::unique_ptr<StarpuPlan> build_plan(const ExecGraph& x) override {
    const StepGraph& g = x.graph;
    auto plan = std::make_unique<StarpuPlan>();
    plan->handles.resize(g.data.size());
    for (starpu_data_handle_t& h : plan->handles) starpu_void_data_register(&h);
    plan->registry = registry_;
    registry_->plans.push_back(plan.get());
    const auto n = static_cast<TaskId>(g.tasks.size());
    plan->begin.reserve(n + 1);
    // Per-writer lowering (the default) leaves one CW writer per datum and group, followed
    // by its reducer: program order there keeps the sum's order deterministic (as for
    // worksteal and barrier; the reducer also waits for the first writer). Without it, StarPU
    // commutes the writers.
    const bool commute = x.scope != ReduceScope::kPerWriter;
    std::vector<Access> merged;
    for (TaskId t = 0; t < n; ++t) {
      plan->begin.push_back(static_cast<std::uint32_t>(plan->buffer.size()));
      // A datum listed twice by one task becomes one buffer (StarPU wants distinct handles).
      merged.clear();
      for (const Access& a : g.accesses_of(t)) {
        bool found = false;
        for (Access& m : merged)
          if (m.datum == a.datum) {
            if (m.mode != a.mode) m.mode = AccessMode::RW;
            found = true;
          }
        if (!found) merged.push_back(a);
      }
      bool ordered = false;  // a W or RW access orders consecutive instances already
      for (const Access& m : merged) {
        plan->buffer.push_back(m.datum);
        // Per-thread temporaries: a group's writers run in any order, even at once, each on
        // its thread's temporary; R on the block's first orders them after the previous
        // reducer and before the next (RW), as RW or COMMUTE would not.
        plan->mode.push_back(x.thread_temps != 0 && m.mode == AccessMode::CW &&
                                     x.datum_origin[m.datum] != m.datum
                                 ? STARPU_R
                                 : to_starpu(m.mode, commute));
        ordered |= m.mode == AccessMode::W || m.mode == AccessMode::RW;
      }
      if (g.tasks[t].loop != kNoLoop && !ordered) {
        plan->buffer.push_back(static_cast<std::uint32_t>(plan->handles.size()));
        plan->mode.push_back(STARPU_RW);
        plan->handles.emplace_back();
        starpu_void_data_register(&plan->handles.back());
      }
    }
    plan->begin.push_back(static_cast<std::uint32_t>(plan->buffer.size()));
    return plan;
  }

  static void body(void* buffers[], void* arg) {
    (void)buffers;  // void handles: the bodies reach their data through the workload
    TGRAPH_TSAN_ACQUIRE(&g_submit_token);
    auto* in = static_cast<Instance*>(arg);
    in->ex->run_instance(*in);
  }

  void run_instance(Instance& in) {
    const int id = starpu_worker_get_id();
    const auto thread = static_cast<std::uint32_t>(id < 0 ? 0 : id) % options().threads;
    const StarpuPlan& p = *step_.plan;
    if constexpr (kTsan) {
      // StarPU's queues and dependency release are not instrumented: make the hand-off from
      // the previous accessors of each handle visible to TSan (the submitter's: see body).
      for (auto b = p.begin[in.task]; b < p.begin[in.task + 1]; ++b)
        TGRAPH_TSAN_ACQUIRE(&p.handles[p.buffer[b]]);
    }
    // relaxed: only skips work after a failure; the error itself is passed under a mutex.
    if (!failed_.load(std::memory_order_relaxed)) {
      try {
        const ExecGraph& x = *step_.exec;
        ThreadCounters& tc = counters_[thread];
        if (!observers().empty()) detail::notify_begin(observers(), thread, in.task, in.iteration);
        step_.workload->run(TaskRun{&x, in.task, x.origin[in.task], in.iteration, thread});
        if (!observers().empty()) detail::notify_end(observers(), thread, in.task, in.iteration);
        ++tc.tasks;
        const LoopId l = x.graph.tasks[in.task].loop;
        if (in.check == Check::kDecide) {
          in.decision = detail::leave_loop(x, l, in.iteration, *step_.workload) ? 1 : 0;
        } else if (in.check != Check::kNone) {
          // The count is only compared with: any count past the next iteration continues.
          const std::uint32_t count = in.iteration + (in.check == Check::kStop ? 1 : 2);
          in.decision = detail::check_unrolled(x, l, in.iteration, count, *step_.workload) ? 1 : 0;
        }
      } catch (...) {
        fail(std::current_exception());
      }
    }
    if constexpr (kTsan) {
      for (auto b = p.begin[in.task]; b < p.begin[in.task + 1]; ++b)
        TGRAPH_TSAN_RELEASE(&p.handles[p.buffer[b]]);
      TGRAPH_TSAN_RELEASE(&join_token_);
    }
  }

  void fail(std::exception_ptr e) {
    std::lock_guard lock(error_mutex_);
    if (!error_) error_ = std::move(e);
    // relaxed: a hint for the tasks still to run; error_ itself is read under the mutex.
    failed_.store(true, std::memory_order_relaxed);
  }

  /// Submits instance (t, it); returns the task when `wait` (not detached), else nullptr.
  starpu_task* submit(TaskId t, std::uint32_t it, Check check, bool wait) {
    const StarpuPlan& p = *step_.plan;
    instances_.push_back(Instance{this, t, it, check, -1});
    starpu_task* task = starpu_task_create();
    if (task == nullptr) throw std::bad_alloc();
    task->cl = &codelet_;
    task->cl_arg = &instances_.back();
    const std::uint32_t first = p.begin[t];
    const auto nb = static_cast<int>(p.begin[t + 1] - first);
    task->nbuffers = nb;
    if (nb > STARPU_NMAXBUFS) {
      // Freed by StarPU with the task.
      task->dyn_handles =
          static_cast<starpu_data_handle_t*>(std::malloc(sizeof(starpu_data_handle_t) * nb));
      task->dyn_modes =
          static_cast<starpu_data_access_mode*>(std::malloc(sizeof(starpu_data_access_mode) * nb));
      if (task->dyn_handles == nullptr || task->dyn_modes == nullptr) {
        starpu_task_destroy(task);
        throw std::bad_alloc();
      }
    }
    for (int i = 0; i < nb; ++i) {
      STARPU_TASK_SET_HANDLE(task, p.handles[p.buffer[first + i]], i);
      STARPU_TASK_SET_MODE(task, p.mode[first + i], i);
    }
    if (wait) task->detach = 0;  // destroyed by starpu_task_wait
    TGRAPH_TSAN_RELEASE(&g_submit_token);
    if (const int rc = starpu_task_submit(task); rc != 0) {
      starpu_task_destroy(task);
      throw Error("StarPU: starpu_task_submit failed (" + std::to_string(rc) + ")");
    }
    return wait ? task : nullptr;
  }

  /// Submits the whole step (loops unrolled or host-synchronised); returns early on failure.
  void submit_step(const ExecGraph& x, Workload& w, ExecStepStats& stats) {
    const StepGraph& g = x.graph;
    detail::walk_step(
        g, [this] { return failed_.load(std::memory_order_relaxed); },  // relaxed: see fail()
        [this](TaskId t) { submit(t, 0, Check::kNone, false); },
        [&](LoopId l) {
          const Loop& loop = g.loops[l];
          if (const std::optional<std::uint32_t> known = w.known_iterations(l)) {
            // Unrolled: the break tasks still evaluate the condition, which must agree.
            const std::uint32_t count = detail::unrolled_count(loop, *known);
            for (std::uint32_t it = 0; it < count; ++it)
              for (TaskId u = loop.first; u < loop.last; ++u)
                submit(u, it,
                       u + 1 < loop.last ? Check::kNone
                                         : (it + 1 == count ? Check::kStop : Check::kContinue),
                       false);
            stats.loop_iterations[l] = count;
          } else {
            for (std::uint32_t it = 0;; ++it) {
              for (TaskId u = loop.first; u + 1 < loop.last; ++u)
                submit(u, it, Check::kNone, false);
              starpu_task* brk = submit(loop.last - 1, it, Check::kDecide, true);
              const Instance& in = instances_.back();
              if (const int rc = starpu_task_wait(brk); rc != 0)
                throw Error("StarPU: starpu_task_wait failed (" + std::to_string(rc) + ")");
              TGRAPH_TSAN_ACQUIRE(&join_token_);
              stats.loop_iterations[l] = it + 1;
              if (in.decision != 0) break;  // leave, or the break task did not run (failure)
            }
          }
        });
  }

  void run(StarpuPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override {
    const StepGraph& g = x.graph;
    if (fresh) detail::touch_all(g, w);  // no affinity: touched by the calling thread
    if (options().pin) main_binding_.save_once();  // restored when the executor is destroyed
    detail::bind_current_thread(options().pin, 0);  // the submitter on slot 0's core
    step_ = {&plan, &x, &w};
    instances_.clear();
    error_ = nullptr;
    failed_.store(false, std::memory_order_relaxed);  // relaxed: no task runs now
    counters_.reset();
    stats.loop_iterations.assign(g.loops.size(), 0);
    starpu_resume();
    try {
      submit_step(x, w, stats);
    } catch (...) {
      fail(std::current_exception());
    }
    starpu_task_wait_for_all();  // never leave a submitted task behind, even on error
    starpu_pause();
    TGRAPH_TSAN_ACQUIRE(&join_token_);
    counters_.copy_to(stats);
    std::exception_ptr error;
    {
      std::lock_guard lock(error_mutex_);
      error = error_;
    }
    if (error) std::rethrow_exception(error);
  }

  std::shared_ptr<Registry> registry_;
  detail::ThreadSlots counters_;
  detail::MainThreadBinding main_binding_;
  starpu_codelet codelet_{};
  detail::StepContext<StarpuPlan> step_;
  std::deque<Instance> instances_;  // this step's instances (stable addresses)
  std::atomic<bool> failed_{false};
  std::mutex error_mutex_;
  std::exception_ptr error_;
  char join_token_ = 0;  // TSan: address standing for starpu_task_wait(_for_all)
};

}  // namespace

std::unique_ptr<Executor> make_starpu_executor(const ExecOptions& o) {
  return std::make_unique<StarpuExecutor>(o);
}

std::optional<std::uint32_t> max_threads(Policy policy) {
  if (policy == Policy::kStarpu) return static_cast<std::uint32_t>(STARPU_MAXCPUS);
  return std::nullopt;
}

}  // namespace tgraph::replay

#else  // !TGRAPH_HAVE_STARPU

namespace tgraph::replay {

std::unique_ptr<Executor> make_starpu_executor(const ExecOptions& o) {
  (void)o;
  throw OptionError("policy",
                    "starpu needs StarPU, and tgraph was built without StarPU (install Debian's "
                    "libstarpu-dev, pkg-config starpu-1.3, and configure again)");
}

std::optional<std::uint32_t> max_threads(Policy /*policy*/) { return std::nullopt; }

}  // namespace tgraph::replay

#endif
