// SPDX-License-Identifier: MIT
// StarPU-MPI as the distributed peer (the MPI replay's starpu-mpi policy): the same
// lowered graph (cumulative writes through per-processor reducers, as tgraph's own schedule
// runs them: Debian's StarPU 1.3 has no STARPU_MPI_REDUX), the same bodies (RankWorkload) and
// the same ownership, submitted the way StarPU-MPI applications are written:
//
// - every rank registers every datum (a vector handle on the workload's own buffer, home
//   node main RAM) and calls starpu_mpi_data_register with its owner, the rank of the
//   datum's first writer in the step (a datum the step only reads keeps its owner);
//   starpu_mpi_data_migrate moves ownership when a repartition changes that rank;
// - every rank submits every task instance, in program order, with starpu_mpi_task_insert,
//   STARPU_EXECUTE_ON_NODE the rank of the task's processor and STARPU_EXECUTE_ON_WORKER its
//   thread there; StarPU-MPI posts the transfers itself (a reader's rank receives a version
//   once and caches it until the next write; a write on a rank that does not own the datum
//   is sent back to the owner);
// - dynamic loops are unrolled by their recorded counts (the break task still evaluates the
//   condition, which must agree), as for the threaded baselines.
//
// The buffers StarPU hands a task must be the workload's own (CPU workers only: a handle's
// main-RAM copy is its home buffer); the codelet checks it, so a run whose data went
// elsewhere fails instead of checking the wrong words.
#include "run_common.hpp"
#include "tgraph/graph/error.hpp"

#if defined(TGRAPH_HAVE_STARPU_MPI)

#include <starpu.h>
#include <starpu_mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

#include "tgraph/replay/starpu_modes.hpp"

namespace tgraph::mpi {
namespace {

/// What the codelet receives (packed by StarPU with STARPU_VALUE on the executing rank).
struct InstanceArg {
  TaskId task = 0;
  std::uint32_t iteration = 0;
  std::int32_t stop = -1;  ///< break task: 1 the loop must stop after it, 0 go on; else -1
};

class StarpuMpiRun;
StarpuMpiRun* g_run = nullptr;  // the one StarPU-MPI runtime of this process, for the codelet

using replay::to_starpu;  // CW: one processor's writers of one datum, in program order

/// A registered datum: its handle, the buffer it was registered on and its owner.
struct Registered {
  starpu_data_handle_t handle = nullptr;
  const std::uint64_t* ptr = nullptr;
  std::size_t words = 0;
  int owner = 0;
};

class StarpuMpiRun {
 public:
  StarpuMpiRun(const Layout& layout, RankWorkload& w) : layout_(layout), w_(w) {
    if (layout.threads_per_rank > STARPU_MAXCPUS)
      throw OptionError("policy", "starpu-mpi: {threads_per_rank} " +
                                      std::to_string(layout.threads_per_rank) +
                                      ": this StarPU has at most " +
                                      std::to_string(STARPU_MAXCPUS) + " CPU workers");
    // Banners would spoil a JSON report; byte counts per destination need the statistics;
    // several ranks share a machine, so StarPU must not bind each rank's workers to cores
    // 0..T-1.
    setenv("STARPU_SILENT", "1", 0);
    setenv("STARPU_COMM_STATS", "1", 1);
    setenv("STARPU_WORKERS_NOBIND", "1", 0);
    starpu_conf conf;
    replay::cpu_only_conf(conf, layout.threads_per_rank);
    if (const int rc = starpu_mpi_init_conf(nullptr, nullptr, 0, MPI_COMM_WORLD, &conf); rc != 0)
      throw Error("StarPU-MPI: starpu_mpi_init_conf failed (" + std::to_string(rc) + ")");
    g_run = this;
    const unsigned got = starpu_cpu_worker_get_count();
    if (got != layout.threads_per_rank) {
      shutdown();
      throw OptionError("policy", "starpu-mpi: asked for " +
                                      std::to_string(layout.threads_per_rank) +
                                      " CPU workers per rank, StarPU-MPI started " +
                                      std::to_string(got));
    }
    workers_.resize(layout.threads_per_rank);
    starpu_worker_get_ids_by_type(STARPU_CPU_WORKER, workers_.data(),
                                  static_cast<unsigned>(workers_.size()));
    starpu_codelet_init(&codelet_);
    codelet_.where = STARPU_CPU;
    codelet_.cpu_funcs[0] = &StarpuMpiRun::body;
    codelet_.nbuffers = STARPU_VARIABLE_NBUFFERS;
    codelet_.name = "tgraph";
    MPI_Comm_rank(MPI_COMM_WORLD, &me_);
    sent_before_.assign(layout.ranks, 0);
  }

  ~StarpuMpiRun() { shutdown(); }
  StarpuMpiRun(const StarpuMpiRun&) = delete;
  StarpuMpiRun& operator=(const StarpuMpiRun&) = delete;

  /// Makes the handles follow the bound plan: temporaries of the previous plan go, the
  /// plan's data are registered (again when the workload reallocated a buffer), each owned
  /// by the rank of its first writer; returns the bytes that changed owner (migrated).
  std::uint64_t prepare(const Plan& plan, const StepGraph& step, bool rebound) {
    const StepGraph& g = plan.exec.graph;
    const std::size_t n_orig = step.data.size();
    if (rebound) {
      for (Registered& r : temps_) unregister(r);
      temps_.clear();
    }
    if (orig_.size() < n_orig) orig_.resize(n_orig);
    temps_.resize(g.data.size() > n_orig ? g.data.size() - n_orig : 0);
    // The rank of each datum's first writer (program order; loop bodies in task order).
    std::vector<int> writer(g.data.size(), -1), reader(g.data.size(), -1);
    for (TaskId t = 0; t < g.tasks.size(); ++t) {
      const int rank = static_cast<int>(layout_.rank_of(plan.exec.assignment.proc[t]));
      for (const Access& a : g.accesses_of(t)) {
        if (writes(a.mode) && writer[a.datum] < 0) writer[a.datum] = rank;
        if (reader[a.datum] < 0) reader[a.datum] = rank;
      }
    }
    std::uint64_t migrated = 0;
    for (DatumId d = 0; d < g.data.size(); ++d) {
      Registered& r = d < n_orig ? orig_[d] : temps_[d - n_orig];
      const auto words = w_.words(d);
      const int owner = writer[d] >= 0 ? writer[d] : (r.handle ? r.owner : std::max(0, reader[d]));
      if (r.handle && (r.ptr != words.data() || r.words != words.size())) unregister(r);
      if (!r.handle) {
        register_datum(r, words, owner);
      } else if (r.owner != owner) {
        starpu_mpi_data_migrate(MPI_COMM_WORLD, r.handle, owner);
        r.owner = owner;
        migrated += starpu_data_get_size(r.handle);
      }
    }
    // Each exec task's buffers: one per distinct datum (StarPU wants distinct handles).
    begin_.assign(1, 0);
    descr_.clear();
    datum_.clear();
    for (TaskId t = 0; t < g.tasks.size(); ++t) {
      const std::size_t first = descr_.size();
      for (const Access& a : g.accesses_of(t)) {
        const Registered& r = a.datum < n_orig ? orig_[a.datum] : temps_[a.datum - n_orig];
        bool merged = false;
        for (std::size_t i = first; i < descr_.size(); ++i)
          if (datum_[i] == a.datum) {
            if (descr_[i].mode != to_starpu(a.mode)) descr_[i].mode = STARPU_RW;
            merged = true;
          }
        if (merged) continue;
        descr_.push_back(starpu_data_descr{r.handle, to_starpu(a.mode)});
        datum_.push_back(a.datum);
      }
      begin_.push_back(static_cast<std::uint32_t>(descr_.size()));
    }
    return migrated;
  }

  /// Submits every instance of the step on this rank (StarPU-MPI runs each where
  /// EXECUTE_ON_NODE says and posts the transfers), waits for all of them and for every
  /// transfer. Returns the number of instances this rank ran.
  std::uint64_t run_step(const Plan& plan, const StepGraph& step, std::size_t si,
                         double watchdog_s) {
    exec_ = &plan.exec;
    const StepGraph& g = plan.exec.graph;
    std::uint64_t mine = 0;
    auto insert = [&](TaskId t, std::uint32_t it, std::int32_t stop) {
      const ProcId p = plan.exec.assignment.proc[t];
      const int rank = static_cast<int>(layout_.rank_of(p));
      const int worker = workers_[p % layout_.threads_per_rank];
      mine += rank == me_ ? 1 : 0;
      InstanceArg arg{t, it, stop};
      const int rc = starpu_mpi_task_insert(
          MPI_COMM_WORLD, &codelet_, STARPU_DATA_MODE_ARRAY, descr_.data() + begin_[t],
          static_cast<int>(begin_[t + 1] - begin_[t]), STARPU_EXECUTE_ON_NODE, rank,
          STARPU_EXECUTE_ON_WORKER, worker, STARPU_VALUE, &arg, sizeof(arg), 0);
      if (rc != 0)
        throw Error("StarPU-MPI: starpu_mpi_task_insert failed (" + std::to_string(rc) + ")");
    };
    done_.store(0, std::memory_order_relaxed);
    Watchdog dog(*this, si, watchdog_s);
    std::vector<LoopId> loop_at(g.tasks.size(), kNoLoop);
    for (LoopId l = 0; l < g.loops.size(); ++l) loop_at[g.loops[l].first] = l;
    for (TaskId t = 0; t < g.tasks.size();) {
      const LoopId l = loop_at[t];
      if (l == kNoLoop) {
        insert(t, 0, -1);
        ++t;
        continue;
      }
      const Loop& loop = g.loops[l];
      const std::uint32_t n = std::max<std::uint32_t>(1, step.loops[l].iterations);
      for (std::uint32_t it = 0; it < n; ++it)
        for (TaskId u = loop.first; u < loop.last; ++u)
          insert(u, it, u + 1 < loop.last ? -1 : (it + 1 == n ? 1 : 0));
      t = loop.last;
    }
    dog.expect(mine);
    starpu_task_wait_for_all();
    starpu_mpi_wait_for_all(MPI_COMM_WORLD);  // and every detached transfer
    dog.stop();
    std::lock_guard lock(error_mu_);
    if (!error_.empty()) {
      std::fprintf(stderr, "tgraph-mpi: rank %d: %s\n", me_, error_.c_str());
      std::fflush(stderr);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    return mine;
  }

  /// Bytes this rank sent to each rank since the previous call (STARPU_COMM_STATS).
  std::vector<std::uint64_t> sent_bytes() {
    std::vector<std::size_t> now(layout_.ranks, 0);
    starpu_mpi_comm_amounts_retrieve(now.data());
    std::vector<std::uint64_t> out(layout_.ranks);
    for (std::uint32_t r = 0; r < layout_.ranks; ++r) {
      out[r] = now[r] - sent_before_[r];
      sent_before_[r] = now[r];
    }
    return out;
  }

  /// The sum of datum_hash over the data [0, n) this rank owns (their latest versions).
  std::uint64_t owned_hash(std::size_t n) {
    std::uint64_t part = 0;
    for (DatumId d = 0; d < n && d < orig_.size(); ++d) {
      const Registered& r = orig_[d];
      if (!r.handle || r.owner != me_) continue;
      starpu_data_acquire(r.handle, STARPU_R);
      part += datum_hash(d, w_.words(d));
      starpu_data_release(r.handle);
    }
    return part;
  }

 private:
  /// Names this rank when its own instances stop finishing for watchdog_s (a StarPU-MPI
  /// transfer that never comes), then ends the job.
  class Watchdog {
   public:
    Watchdog(StarpuMpiRun& run, std::size_t step, double seconds)
        : run_(run), step_(step), seconds_(seconds) {
      if (seconds_ > 0) thread_ = std::thread([this] { watch(); });
    }
    ~Watchdog() { stop(); }
    void expect(std::uint64_t mine) { expected_.store(mine, std::memory_order_relaxed); }
    void stop() {
      {
        std::lock_guard lock(mu_);
        stopped_ = true;
      }
      cv_.notify_all();
      if (thread_.joinable()) thread_.join();
    }

   private:
    void watch() {
      std::uint64_t seen = 0;
      auto last = std::chrono::steady_clock::now();
      std::unique_lock lock(mu_);
      while (!cv_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stopped_; })) {
        // relaxed: counters for a timeout, not for ordering data.
        const std::uint64_t done = run_.done_.load(std::memory_order_relaxed);
        const std::uint64_t expected = expected_.load(std::memory_order_relaxed);
        const auto now = std::chrono::steady_clock::now();
        if (done != seen || done >= expected) {
          seen = done;
          last = now;
          continue;
        }
        if (std::chrono::duration<double>(now - last).count() < seconds_) continue;
        std::fprintf(stderr,
                     "tgraph-mpi: rank %d: starpu-mpi: no task of step %zu finished for %g s "
                     "(%llu of this rank's %llu ran; a transfer never arrived)\n",
                     run_.me_, step_, seconds_, static_cast<unsigned long long>(done),
                     static_cast<unsigned long long>(expected));
        std::fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, 1);
      }
    }
    StarpuMpiRun& run_;
    std::size_t step_;
    double seconds_;
    std::atomic<std::uint64_t> expected_{~0ull};
    std::mutex mu_;
    std::condition_variable cv_;
    bool stopped_ = false;
    std::thread thread_;
  };

  void register_datum(Registered& r, std::span<const std::uint64_t> words, int owner) {
    r.ptr = words.data();
    r.words = words.size();
    r.owner = owner;
    // A datum without words (recorded size 0, or touch off) still orders its accessors.
    std::uint64_t* home = const_cast<std::uint64_t*>(words.data());
    std::size_t n = words.size();
    if (n == 0) {
      home = &empty_.emplace_back(0);
      n = 1;
    }
    starpu_vector_data_register(&r.handle, STARPU_MAIN_RAM, reinterpret_cast<uintptr_t>(home),
                                static_cast<std::uint32_t>(n), sizeof(std::uint64_t));
    starpu_mpi_data_register(r.handle, next_tag_++, owner);
  }

  static void unregister(Registered& r) {
    if (r.handle) starpu_data_unregister_no_coherency(r.handle);
    r = Registered{};
  }

  static void body(void* buffers[], void* cl_arg) {
    InstanceArg arg;
    starpu_codelet_unpack_args(cl_arg, &arg);
    g_run->run_instance(arg, buffers);
  }

  void run_instance(const InstanceArg& arg, void* buffers[]) {
    try {
      const ExecGraph& x = *exec_;
      for (std::uint32_t i = begin_[arg.task]; i < begin_[arg.task + 1]; ++i) {
        const auto words = w_.words(datum_[i]);
        const void* got = reinterpret_cast<const void*>(
            STARPU_VECTOR_GET_PTR(buffers[i - begin_[arg.task]]));
        if (!words.empty() && got != words.data())
          throw std::logic_error("StarPU-MPI handed a task a copy of datum " +
                                 std::to_string(datum_[i]) + " instead of its home buffer");
      }
      const int worker = starpu_worker_get_id();
      replay::TaskRun r;
      r.exec = &x;
      r.task = arg.task;
      r.origin = x.origin[arg.task];
      r.iteration = arg.iteration;
      r.thread = static_cast<std::uint32_t>(worker < 0 ? 0 : worker) % layout_.threads_per_rank;
      w_.run(r);
      if (arg.stop >= 0) {
        const bool stop = w_.stop_after(x.graph.tasks[arg.task].loop, arg.iteration);
        if (stop != (arg.stop == 1))
          throw std::logic_error("the workload's loop condition differs from its recorded count");
      }
    } catch (const std::exception& e) {
      std::lock_guard lock(error_mu_);
      if (error_.empty()) error_ = e.what();
    }
    // relaxed: a progress count for the watchdog.
    done_.fetch_add(1, std::memory_order_relaxed);
  }

  void shutdown() {
    if (g_run != this) return;
    starpu_task_wait_for_all();
    starpu_mpi_cache_flush_all_data(MPI_COMM_WORLD);
    for (Registered& r : temps_) unregister(r);
    for (Registered& r : orig_) unregister(r);
    starpu_mpi_shutdown();
    if (starpu_is_initialized()) starpu_shutdown();
    g_run = nullptr;
  }

  Layout layout_;
  RankWorkload& w_;
  int me_ = 0;
  std::vector<int> workers_;  // StarPU worker id of each thread of this rank
  starpu_codelet codelet_{};
  std::vector<Registered> orig_, temps_;
  std::deque<std::uint64_t> empty_;  // home words of data without words
  starpu_mpi_tag_t next_tag_ = 1;    // the same sequence on every rank
  std::vector<std::uint32_t> begin_;       // exec task -> first of its buffers
  std::vector<starpu_data_descr> descr_;   // buffers: handle and mode
  std::vector<DatumId> datum_;             // buffers: exec datum
  const ExecGraph* exec_ = nullptr;
  std::vector<std::size_t> sent_before_;
  std::atomic<std::uint64_t> done_{0};
  std::mutex error_mu_;
  std::string error_;
};

}  // namespace

bool have_starpu_mpi() { return true; }

MpiReplayResult replay_starpu_mpi(const Trace& trace, const TraceAssignment& assignment,
                                  const MpiReplayOptions& options) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::size_t steps = 0;
  const Layout layout = checked_layout(trace, assignment, options, steps);
  if (options.test_drop_message)
    throw OptionError("test_drop_message", "not with {policy} starpu-mpi");
  MpiReplayResult result;
  result.policy = MpiPolicy::kStarpuMpi;
  result.ranks = layout.ranks;
  result.threads_per_rank = layout.threads_per_rank;
  const double touch_ns_per_byte = shared_touch_rate();
  RankWorkload w(touch_ns_per_byte);
  PlanCache plans;
  RepartitionWatch watch;
  Holders holders = everywhere(0, layout.ranks);  // tgraph's schedule: the prediction
  {
    StarpuMpiRun run(layout, w);
    for (std::size_t si = 0; si < steps; ++si) {
      const StepGraph& step = trace.steps[si];
      const PreparedStep prepared =
          prepare_step(trace, assignment, si, layout, plans, w, holders, watch);
      holders = prepared.schedule.holders_after;
      MpiStepResult sr;
      sr.predicted = prepared.schedule.traffic;
      sr.repartitioned = prepared.repartitioned;
      const std::int64_t t0 = start_step(step, options, w);
      const Plan* plan = prepared.plan;
      const bool rebound = prepared.rebound;
      const std::uint64_t migrated = run.prepare(*plan, step, rebound);
      run.run_step(*plan, step, si, options.watchdog_s);
      const std::vector<std::uint64_t> sent = run.sent_bytes();
      std::vector<std::uint64_t> sums(static_cast<std::size_t>(layout.ranks) * layout.ranks, 0);
      std::copy(sent.begin(), sent.end(), sums.begin() + rank * layout.ranks);
      sum_to_root(sums);
      sr.wall_ns = now_ns() - t0;
      if (rank != 0) continue;
      sr.measured = Traffic(layout.ranks);
      sr.measured.bytes = sums;
      sr.migrated_bytes = si > 0 ? migrated : 0;
      result.wall_ns += sr.wall_ns;
      result.steps.push_back(std::move(sr));
    }
    const std::size_t n_orig = steps > 0 ? trace.steps[steps - 1].data.size() : 0;
    std::vector<std::uint64_t> sum = {run.owned_hash(n_orig)};
    sum_to_root(sum);
    result.checksum = sum[0];
  }
  sequential_reference(trace, steps, options, touch_ns_per_byte, result);
  return result;
}

}  // namespace tgraph::mpi

#else  // !TGRAPH_HAVE_STARPU_MPI

namespace tgraph::mpi {

bool have_starpu_mpi() { return false; }

MpiReplayResult replay_starpu_mpi(const Trace&, const TraceAssignment&,
                                  const MpiReplayOptions&) {
  throw OptionError("policy",
                    "starpu-mpi: tgraph-mpi was built without StarPU-MPI (Debian libstarpu-dev, "
                    "pkg-config starpumpi-1.3; not in an SMPI build)");
}

}  // namespace tgraph::mpi

#endif
