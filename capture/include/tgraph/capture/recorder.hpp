// SPDX-License-Identifier: MIT
// The instrumentation API an engine's coordination code calls (paper section 3.1).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <ranges>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "tgraph/graph/access_check.hpp"
#include "tgraph/graph/cumulative.hpp"
#include "tgraph/graph/incremental.hpp"
#include "tgraph/graph/step_graph.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

namespace tgraph::capture {

namespace detail {
/// A cheap monotonic tick: the invariant TSC on x86 (about a third of a steady_clock read),
/// else steady_clock nanoseconds. Ticks are converted to ns once per step (end_step), from
/// the steady_clock time the step took.
inline std::uint64_t ticks() {
#if defined(__x86_64__) || defined(__i386__)
  return __rdtsc();
#else
  return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}
}  // namespace detail

/// What a Recorder does with the tasks the coordination code issues.
enum class Mode : std::uint8_t {
  kOff = 0,       ///< run task bodies immediately, record nothing (uninstrumented baseline)
  kCapture = 1,   ///< run task bodies immediately, time them, record the step graph
  kDeferred = 2,  ///< record the graph and keep the bodies; nothing runs (live replay)
};

/// "off", "capture" or "deferred".
std::string_view to_string(Mode mode);

/// The API call in which the recorder saw a misuse.
enum class Call : std::uint8_t {
  kBeginStep = 0,
  kEndStep = 1,
  kTask = 2,  ///< task() or a Scope
  kBeginLoop = 3,
  kConditionalBreak = 4,
  kEndLoop = 5,
  kAccumulator = 6,
};

/// "begin_step", "end_step", "task", "begin_loop", "conditional_break", "end_loop",
/// "accumulator".
std::string_view to_string(Call call);

/// One misuse of the API, as the recorder saw it (Recorder::misuses).
struct Misuse {
  Call call = Call::kTask;
  std::string problem;      ///< what was wrong ("the loop was closed by end_loop")
  std::string loop;         ///< the loop concerned, by its condition datum; empty: none
  std::uint64_t step = 0;   ///< the step (0-based: begin_step calls before it)
  std::uint32_t tasks = 0;  ///< tasks that step had recorded when it happened
};

/// "conditional_break: the loop was closed by end_loop (loop 0 on solver.converged, step 3,
/// after 12 tasks)".
std::string to_string(const Misuse& m);

/// A step recorded in deferred mode: the graph plus the bodies to run.
///
/// bodies[t] runs task t; conditions[l] evaluates loop l's break condition after an
/// iteration (true = leave the loop). An executor runs each loop body until its
/// condition holds or `max_iterations` is reached, and sets `Loop::iterations`.
struct StepProgram {
  StepGraph graph;
  std::vector<std::function<void()>> bodies;
  std::vector<std::function<bool()>> conditions;
  /// By datum: how its CW writers can be redirected to temporaries (Recorder::accumulator),
  /// or nullptr. Owned by the recorder.
  std::vector<const Accumulator*> accumulators;
};

/// Records the tasks of each step. Cheap on the hot path: no allocation per task once
/// the step's vectors have grown, two clock reads per task, never throws.
///
///   Recorder rec(Mode::kCapture);
///   ObjectId bar = rec.object("bar0");
///   DatumId x = rec.datum("bar0.x", bar, n * 24), f = rec.datum("bar0.f", bar, n * 24);
///   KindId add_force = rec.kind("addForce");
///   rec.begin_step();
///   rec.task(add_force, bar, {{x, AccessMode::R}, {f, AccessMode::CW}}, [&] { ff.add_force(); });
///   StepGraph g = rec.end_step();
///
/// Dynamic loops (do-while; the break is tested after each full iteration):
///
///   LoopId l = rec.begin_loop(cond, max_iter);
///   do { rec.task(...); ... } while (!rec.conditional_break(l, [&] { return res < tol; }));
///   rec.end_loop(l);
///
/// In capture mode the body is recorded on the first iteration and later iterations add
/// their measured cost to the same tasks. Loop bodies are timed in their first
/// kAlwaysTimed iterations and then every kTimeEvery-th one (iterations of a solver loop do
/// the same work; reading the clock around every run of a sub-microsecond task would cost
/// several percent of the step); a loop task's cost is the mean over its timed iterations,
/// leaving out the longest one when there are 3 or more and it is over 4x the mean of the
/// others, so that one preemption by the OS does not inflate the span; in deferred mode conditional_break returns true
/// after recording the body once, and the executor iterates.
///
/// Cost passes (set_cost_passes(N), the cost passes of `tgraph capture`): in capture mode each
/// timed run of a task body, in a loop or not, runs N times and counts the median of the N
/// timings, so that one preempted run does not set the task's cost. Before the first pass
/// the recorder copies the data the task writes (W, RW, CW) from their storage (the `ptr`
/// given to datum()), and restores them before every later pass: each pass starts from the
/// same state and the state after the task is what one run leaves, bit for bit. A task that
/// writes a datum declared without storage cannot be restored and is timed once
/// (single_pass_runs() counts them). Bodies must depend only on the data they declare, as
/// the dataflow graph assumes anyway. Scopes (RAII) and break conditions are timed once.
class Recorder {
 public:
  /// Loop iterations always timed in capture mode.
  static constexpr std::uint32_t kAlwaysTimed = 3;
  /// After those, one iteration in kTimeEvery is timed.
  static constexpr std::uint32_t kTimeEvery = 4;

  explicit Recorder(Mode mode = Mode::kCapture);
  ~Recorder();
  Recorder(Recorder&&) noexcept;
  Recorder& operator=(Recorder&&) noexcept;

  /// Current mode.
  Mode mode() const { return mode_; }
  /// Timed passes of every task body in capture mode (median kept; default 1; 0 counts as 1).
  void set_cost_passes(std::uint32_t passes) { cost_passes_ = passes == 0 ? 1 : passes; }
  /// Timed passes per task body (set_cost_passes).
  std::uint32_t cost_passes() const { return cost_passes_; }
  /// Task runs timed once although cost passes were asked: they write a datum declared
  /// without storage, which the recorder cannot restore between passes. Since construction.
  std::uint64_t single_pass_runs() const { return single_pass_runs_; }
  /// Whether end_step() derives the graph's edges (default true). A capture that only
  /// streams steps to a trace file turns it off: traces do not store edges, readers derive
  /// them, and the capture's hot path saves the time.
  void set_derive_edges(bool on) { derive_edges_ = on; }
  /// Whether edges are derived from the previous step's (tgraph::EdgeDeriver: only the data
  /// whose access sequence changed are derived again; default true) or from scratch. Both
  /// give the same edges.
  void set_incremental_edges(bool on) {
    incremental_edges_ = on;
    if (!on) deriver_.reset();
  }
  /// What the last end_step() did to derive the edges (its time in `ns`; all zero when the
  /// edges were not derived).
  const EdgeUpdate& last_edge_update() const { return last_update_; }

  /// Declares an object (or interaction) with a name that is stable across steps.
  /// Declaring an existing name returns its id.
  ObjectId object(std::string_view name);
  /// Declares a datum; persistent across steps. `ptr` (optional) is its storage, used by
  /// live replay for first touch and state comparison.
  DatumId datum(std::string_view name, ObjectId owner, std::uint64_t bytes, void* ptr = nullptr);
  /// Interns a task kind (method name).
  KindId kind(std::string_view name);

  /// Every datum declared so far (persistent across steps).
  const std::vector<Datum>& data() const { return data_; }
  /// Storage pointer given for datum `d` (nullptr if none).
  void* datum_ptr(DatumId d) const { return ptrs_[d]; }
  /// Declares that the CW writers of datum `d` add into `a.target` through
  /// tgraph::accumulate(), so that a live executor can give them temporaries and reduce
  /// (paper section 3.2). Data without one keep their CW writers in program order live.
  void accumulator(DatumId d, Accumulator a);

  /// Starts recording a step. `host_ns`: what the engine spent on this step before it, on
  /// its main thread outside any task (collision detection, contact bookkeeping); stored
  /// as StepGraph::host_ns so that replays and the simulator pay it too.
  void begin_step(std::uint64_t host_ns = 0);
  /// Sets the step's contact set (object pairs) and collision group per object.
  void set_contacts(std::vector<Contact> contacts, std::vector<std::uint32_t> groups);
  /// Ends the step and returns its graph with edges derived (empty graph in kOff mode).
  StepGraph end_step();
  /// Ends a deferred step: its graph (edges derived) and task bodies.
  StepProgram end_step_program();

  /// Issues one task: runs (and in capture mode times) `body` now, or keeps it (deferred).
  template <class F>
  void task(KindId kind, ObjectId obj, std::initializer_list<Access> acc, F&& body) {
    issue(kind, obj, acc.begin(), acc.size(), std::forward<F>(body));
  }
  /// Same, with the accesses in any range of Access: a std::vector or std::array built at
  /// run time, a std::span, or a view yielding Access (copied into a buffer kept by the
  /// recorder, so no allocation once it has grown).
  ///
  ///   std::vector<Access> acc = {{x, AccessMode::R}};
  ///   for (DatumId f : touched) acc.push_back({f, AccessMode::CW});
  ///   rec.task(add_force, obj, acc, [&] { ff.add_force(); });
  template <std::ranges::input_range R, class F>
  requires std::convertible_to<std::ranges::range_reference_t<R>, Access>
  void task(KindId kind, ObjectId obj, R&& acc, F&& body) {
    if constexpr (std::ranges::contiguous_range<R> && std::ranges::sized_range<R> &&
                  std::same_as<std::ranges::range_value_t<R>, Access>) {
      issue(kind, obj, std::ranges::data(acc), std::ranges::size(acc), std::forward<F>(body));
    } else {
      range_buffer_.clear();
      if (mode_ != Mode::kOff)
        for (auto&& a : acc) range_buffer_.push_back(static_cast<Access>(a));
      issue(kind, obj, range_buffer_.data(), range_buffer_.size(), std::forward<F>(body));
    }
  }

  /// RAII form: times the enclosing scope as one task (capture mode only; in deferred mode
  /// a scope cannot be deferred, so use task()).
  class Scope {
   public:
    /// At most kMaxAccesses accesses (more are counted as an error and dropped).
    Scope(Recorder& rec, KindId kind, ObjectId obj, std::initializer_list<Access> acc)
        : rec_(rec), kind_(kind), obj_(obj) {
      for (const Access& a : acc) {
        if (n_ == kMaxAccesses) {
          rec_.misuse(Call::kTask, "a Scope takes at most 16 accesses; the others were dropped");
          break;
        }
        acc_[n_++] = a;
      }
      t0_ = detail::ticks();
    }
    ~Scope() {
      if (rec_.mode_ == Mode::kOff) return;
      rec_.record(kind_, obj_, acc_.data(), n_, detail::ticks() - t0_);
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    static constexpr std::size_t kMaxAccesses = 16;
    Recorder& rec_;
    KindId kind_;
    ObjectId obj_;
    std::array<Access, kMaxAccesses> acc_{};
    std::size_t n_ = 0;
    std::uint64_t t0_ = 0;
  };

  /// Opens a dynamic loop whose break condition is the shared datum `condition`.
  LoopId begin_loop(DatumId condition, std::uint32_t max_iterations);
  /// Records the loop's break task (first iteration) and says whether to leave the loop:
  /// capture/off: evaluates `pred` now (or max iterations reached); deferred: keeps `pred`
  /// and returns true so that the body is recorded once.
  template <class P>
  bool conditional_break(LoopId loop, P&& pred) {
    if (mode_ == Mode::kDeferred) {
      record_break(loop, 0);
      conditions_.emplace_back(std::forward<P>(pred));
      return true;
    }
    const std::uint64_t t0 = detail::ticks();
    bool stop = false;
    if (verify_ && mode_ == Mode::kCapture) [[unlikely]] {
      auto evaluate = [&stop, &pred] { stop = pred(); };
      check_condition(loop, BodyRef(evaluate));
    } else {
      stop = pred();
    }
    return record_break(loop, detail::ticks() - t0) || stop;
  }
  /// Closes the loop.
  void end_loop(LoopId loop);

  /// Access verification (capture mode; `tgraph capture --verify-accesses`): every task body
  /// runs between checksums of the data with storage, and again from the same state with
  /// the data it does not declare perturbed (tgraph::AccessChecker: what it sees and what it
  /// cannot), so that a body writing a datum it declares R (or not at all), or reading one
  /// it does not declare, is found; break conditions are checked for writes. Costs several
  /// passes over the state per task (recorded costs then mean nothing); off by default,
  /// and then one untaken branch per task.
  void set_verify_accesses(bool on);
  /// Whether accesses are verified.
  bool verify_accesses() const { return verify_ != nullptr; }
  /// The wrong declarations found since verification was turned on, deduplicated by task,
  /// datum and what was found, in the order seen.
  std::vector<AccessFinding> access_findings() const;
  /// What verification ran (runs, reruns, runs whose reads were not checked); null when off.
  const AccessChecker::Counts* access_counts() const;

  /// Number of API misuses seen (task count changing between iterations, unbalanced
  /// loops...); the hot path never throws, it counts and end_step() reports.
  std::uint64_t errors() const { return errors_; }
  /// The misuses themselves, in the order seen: which call, what, the loop, the step and
  /// its task count (the first kMaxMisuses kept; errors() counts them all).
  const std::vector<Misuse>& misuses() const { return misuses_; }
  /// Misuses counted since the last begin_step() (after end_step(): the step's own). A
  /// trace writer refuses a step with misuses: its graph is not what the engine ran.
  std::uint64_t step_errors() const { return errors_ - errors_before_step_; }
  /// Misuses kept in misuses().
  static constexpr std::size_t kMaxMisuses = 64;

 private:
  template <class F>
  void issue(KindId kind, ObjectId obj, const Access* acc, std::size_t n, F&& body) {
    switch (mode_) {
      case Mode::kOff:
        body();
        return;
      case Mode::kCapture: {
        if (verify_) [[unlikely]] {
          const std::uint64_t t0 = detail::ticks();
          check_task(kind, obj, acc, n, BodyRef(body));
          record(kind, obj, acc, n, detail::ticks() - t0);
          return;
        }
        if (!time_task_) {  // an untimed loop iteration (see kTimeEvery)
          body();
          record(kind, obj, acc, n, 0);
          return;
        }
        if (cost_passes_ > 1) {
          record(kind, obj, acc, n, median_of_passes(acc, n, body));
          return;
        }
        const std::uint64_t t0 = detail::ticks();
        body();
        record(kind, obj, acc, n, detail::ticks() - t0);
        return;
      }
      case Mode::kDeferred:
        if (record(kind, obj, acc, n, 0)) bodies_.emplace_back(std::forward<F>(body));
        return;
    }
  }
  // `ticks` are detail::ticks() units. Returns true when a new task was appended (false for
  // later loop iterations, whose costs add to the task recorded in the first one).
  bool record(KindId kind, ObjectId obj, const Access* acc, std::size_t n, std::uint64_t ticks) {
    if (open_loop_ != kNoLoop && iteration_ > 0) {
      const TaskId t = body_first_ + replay_pos_;
      if (t + 1 < body_last_ && cur_.tasks[t].kind == kind && cur_.tasks[t].object == obj) {
        cost_sum_[t] += ticks;
        if (ticks > cost_max_[t]) cost_max_[t] = ticks;
        ++replay_pos_;
      } else {
        body_changed(t, kind, obj);
      }
      return false;
    }
    return append_task(kind, obj, acc, n, ticks);
  }
  bool append_task(KindId kind, ObjectId obj, const Access* acc, std::size_t n, std::uint64_t ticks);
  // Runs `body` cost_passes_ times from the same state (the written data restored between
  // passes) and returns the median of the timings, in ticks; once when it cannot restore.
  template <class F>
  std::uint64_t median_of_passes(const Access* acc, std::size_t n, F& body) {
    const bool restorable = save_written(acc, n);
    if (!restorable) ++single_pass_runs_;
    const std::uint32_t passes = restorable ? cost_passes_ : 1;
    pass_ticks_.clear();
    for (std::uint32_t p = 0; p < passes; ++p) {
      if (p > 0) restore_written(acc, n);
      const std::uint64_t t0 = detail::ticks();
      body();
      pass_ticks_.push_back(detail::ticks() - t0);
    }
    return median_ticks();
  }
  // Copies the bytes of every datum the accesses write into saved_; false (nothing saved)
  // when one of them has no storage pointer.
  bool save_written(const Access* acc, std::size_t n);
  // Copies saved_ back (the same accesses as the last save_written).
  void restore_written(const Access* acc, std::size_t n);
  // Median of pass_ticks_ (the lower middle one for an even count).
  std::uint64_t median_ticks();
  // Returns true when the loop has reached its maximum iteration count.
  bool record_break(LoopId loop, std::uint64_t ticks);
  // Runs a task body under the access checker; its findings named by the task's key.
  void check_task(KindId kind, ObjectId obj, const Access* acc, std::size_t n, BodyRef body);
  // Evaluates a loop's break condition under the checker (writes only).
  void check_condition(LoopId loop, BodyRef evaluate);
  // Counts a misuse and keeps its description (the first kMaxMisuses); `loop` names the
  // loop concerned (kNoLoop: none).
  void misuse(Call call, std::string problem, LoopId loop = kNoLoop);
  // A loop iteration after the first issued a task other than the first iteration's.
  void body_changed(TaskId expected, KindId kind, ObjectId obj);
  // FNV-1a of a name, cached per object / kind id for stable keys.
  std::uint64_t name_hash(std::vector<std::uint64_t>& cache, std::size_t id, std::string_view name);
  StepGraph finish_step();

  Mode mode_;
  StepGraph cur_;                        // step being recorded
  std::vector<std::string> kinds_;
  std::vector<ObjectInfo> objects_;
  std::vector<Datum> data_;
  std::vector<void*> ptrs_;
  std::vector<std::unique_ptr<Accumulator>> accumulators_;  // by datum (stable addresses)
  std::unordered_map<std::string, ObjectId> object_ids_;
  std::vector<std::uint64_t> cost_sum_;  // per task, ticks summed over iterations
  std::vector<std::uint64_t> cost_max_;  // per task, the longest iteration
  std::vector<std::uint64_t> object_hash_, kind_hash_;  // name hashes (0: not computed)
  std::chrono::steady_clock::time_point step_clock_{};  // begin_step: ticks -> ns per step
  std::uint64_t step_ticks_ = 0;
  std::uint64_t host_ns_ = 0;  // begin_step: the engine's serial time before the step
  std::vector<std::function<void()>> bodies_;
  std::vector<std::function<bool()>> conditions_;
  std::vector<Access> range_buffer_;  // accesses of task() given as a non-contiguous range
  LoopId open_loop_ = kNoLoop;
  std::uint32_t iteration_ = 0;          // current iteration of the open loop (0-based)
  std::uint32_t replay_pos_ = 0;         // next body task to match in iterations > 0
  TaskId body_first_ = 0, body_last_ = 0;  // body of the open loop, once recorded
  bool in_step_ = false;
  bool derive_edges_ = true;
  bool incremental_edges_ = true;
  EdgeDeriver deriver_;       // the previous derived step's edges, by datum
  EdgeUpdate last_update_{};
  bool time_task_ = true;                   // time the tasks of the current iteration
  std::vector<std::uint32_t> loop_timed_;   // per loop: timed iterations so far
  std::uint64_t errors_ = 0;
  std::uint64_t errors_before_step_ = 0;  // errors_ at the last begin_step
  std::uint64_t steps_begun_ = 0;
  std::vector<Misuse> misuses_;
  struct Verify;                    // the checker and its findings (set_verify_accesses)
  std::unique_ptr<Verify> verify_;
  std::uint32_t cost_passes_ = 1;           // timed passes per body (capture mode)
  std::uint64_t single_pass_runs_ = 0;      // runs timed once: unrestorable written data
  std::vector<unsigned char> saved_;        // written data of the task being timed
  std::vector<std::uint64_t> pass_ticks_;   // timings of its passes
};

}  // namespace tgraph::capture
