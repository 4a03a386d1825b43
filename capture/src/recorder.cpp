// SPDX-License-Identifier: MIT
// Recorder: builds the step graph from the coordination code's calls.
#include "tgraph/capture/recorder.hpp"

#include <algorithm>
#include <cstring>
#include <unordered_map>

namespace tgraph::capture {

std::string_view to_string(Mode mode) {
  switch (mode) {
    case Mode::kOff: return "off";
    case Mode::kCapture: return "capture";
    case Mode::kDeferred: return "deferred";
  }
  return "?";
}

std::string_view to_string(Call call) {
  switch (call) {
    case Call::kBeginStep: return "begin_step";
    case Call::kEndStep: return "end_step";
    case Call::kTask: return "task";
    case Call::kBeginLoop: return "begin_loop";
    case Call::kConditionalBreak: return "conditional_break";
    case Call::kEndLoop: return "end_loop";
    case Call::kAccumulator: return "accumulator";
  }
  return "?";
}

std::string to_string(const Misuse& m) {
  std::string s = std::string(to_string(m.call)) + ": " + m.problem + " (";
  if (!m.loop.empty()) s += m.loop + ", ";
  return s + "step " + std::to_string(m.step) + ", after " + std::to_string(m.tasks) + " tasks)";
}

struct Recorder::Verify {
  AccessChecker checker;
  AccessFindings findings;
  std::vector<AccessChecker::Found> found;  // of the run under check
};

Recorder::Recorder(Mode mode) : mode_(mode) {}
Recorder::~Recorder() = default;
Recorder::Recorder(Recorder&&) noexcept = default;
Recorder& Recorder::operator=(Recorder&&) noexcept = default;

void Recorder::set_verify_accesses(bool on) {
  if (!on) {
    verify_.reset();
    return;
  }
  if (verify_) return;
  verify_ = std::make_unique<Verify>();
  for (DatumId d = 0; d < data_.size(); ++d)
    verify_->checker.set_storage(d, ptrs_[d], data_[d].bytes);
  verify_->checker.sync();
}

std::vector<AccessFinding> Recorder::access_findings() const {
  return verify_ ? verify_->findings.list() : std::vector<AccessFinding>{};
}

const AccessChecker::Counts* Recorder::access_counts() const {
  return verify_ ? &verify_->checker.counts() : nullptr;
}

void Recorder::check_task(KindId kind, ObjectId obj, const Access* acc, std::size_t n, BodyRef body) {
  Verify& v = *verify_;
  v.found.clear();
  // Reads in a loop's first two iterations and every 8th (the same tasks run each time).
  const bool reads = open_loop_ == kNoLoop || iteration_ < 2 || iteration_ % 8 == 0;
  v.checker.run({acc, n}, body, reads, v.found);
  if (v.found.empty()) return;
  // The task's id in the step: appended now, or matched in a later loop iteration.
  const TaskId t = open_loop_ != kNoLoop && iteration_ > 0
                       ? body_first_ + replay_pos_
                       : static_cast<TaskId>(cur_.tasks.size());
  std::uint32_t occurrence = 0;
  for (TaskId u = 0; u < t && u < cur_.tasks.size(); ++u)
    if (cur_.tasks[u].kind == kind && cur_.tasks[u].object == obj) ++occurrence;
  const std::string label =
      task_label(kinds_[kind], obj == kNoObject ? std::string_view() : objects_[obj].name, occurrence);
  for (const AccessChecker::Found& f : v.found) v.findings.add(finding(label, f, data_));
}

void Recorder::check_condition(LoopId loop, BodyRef evaluate) {
  Verify& v = *verify_;
  v.found.clear();
  if (loop >= cur_.loops.size()) {
    evaluate();
    v.checker.sync();
    return;
  }
  const Access acc{cur_.loops[loop].condition, AccessMode::R};
  v.checker.run({&acc, 1}, evaluate, false, v.found);
  for (const AccessChecker::Found& f : v.found)
    v.findings.add(finding("loop.break of loop " + std::to_string(loop), f, data_));
}

void Recorder::misuse(Call call, std::string problem, LoopId loop) {
  ++errors_;
  if (misuses_.size() == kMaxMisuses) return;
  Misuse m;
  m.call = call;
  m.problem = std::move(problem);
  if (loop != kNoLoop && loop < cur_.loops.size()) {
    const DatumId c = cur_.loops[loop].condition;
    m.loop = "loop " + std::to_string(loop) + " on " +
             (c < data_.size() ? data_[c].name : "datum " + std::to_string(c));
  }
  m.step = steps_begun_ == 0 ? 0 : steps_begun_ - 1;
  m.tasks = static_cast<std::uint32_t>(cur_.tasks.size());
  misuses_.push_back(std::move(m));
}

void Recorder::body_changed(TaskId expected, KindId kind, ObjectId obj) {
  auto name = [this](KindId k, ObjectId o) {
    std::string s = k < kinds_.size() ? kinds_[k] : "kind " + std::to_string(k);
    if (o != kNoObject) s += " of " + (o < objects_.size() ? objects_[o].name : std::to_string(o));
    return s;
  };
  std::string problem = "iteration " + std::to_string(iteration_) + " issued " + name(kind, obj);
  if (expected + 1 < body_last_)
    problem += " where the first iteration issued " +
               name(cur_.tasks[expected].kind, cur_.tasks[expected].object);
  else
    problem += " after the first iteration's last task (every iteration must issue the same tasks)";
  misuse(Call::kTask, std::move(problem), open_loop_);
}

ObjectId Recorder::object(std::string_view name) {
  const std::string key(name);
  if (auto it = object_ids_.find(key); it != object_ids_.end()) return it->second;
  const auto id = static_cast<ObjectId>(objects_.size());
  objects_.push_back({key});
  object_ids_.emplace(key, id);
  return id;
}

DatumId Recorder::datum(std::string_view name, ObjectId owner, std::uint64_t bytes, void* ptr) {
  data_.push_back({std::string(name), owner, bytes});
  ptrs_.push_back(ptr);
  const auto d = static_cast<DatumId>(data_.size() - 1);
  if (verify_) {
    verify_->checker.set_storage(d, ptr, bytes);
    verify_->checker.sync(d);
  }
  return d;
}

void Recorder::accumulator(DatumId d, Accumulator a) {
  if (d >= data_.size()) {
    misuse(Call::kAccumulator, "datum " + std::to_string(d) + " was not declared");
    return;
  }
  if (accumulators_.size() < data_.size()) accumulators_.resize(data_.size());
  accumulators_[d] = std::make_unique<Accumulator>(std::move(a));
}

KindId Recorder::kind(std::string_view name) {
  for (std::size_t i = 0; i < kinds_.size(); ++i)
    if (kinds_[i] == name) return static_cast<KindId>(i);
  kinds_.emplace_back(name);
  return static_cast<KindId>(kinds_.size() - 1);
}

void Recorder::begin_step(std::uint64_t host_ns) {
  errors_before_step_ = errors_;
  ++steps_begun_;
  if (in_step_) misuse(Call::kBeginStep, "the previous step was not ended (missing end_step)");
  in_step_ = true;
  host_ns_ = host_ns;
  if (verify_) verify_->checker.sync();  // the engine's work between steps
  cur_.tasks.clear();
  cur_.accesses.clear();
  cur_.loops.clear();
  cur_.contacts.clear();
  cur_.groups.clear();
  cost_sum_.clear();
  cost_max_.clear();
  loop_timed_.clear();
  time_task_ = true;
  bodies_.clear();
  conditions_.clear();
  open_loop_ = kNoLoop;
  step_clock_ = std::chrono::steady_clock::now();
  step_ticks_ = detail::ticks();
}

std::uint64_t Recorder::name_hash(std::vector<std::uint64_t>& cache, std::size_t id, std::string_view name) {
  if (cache.size() <= id) cache.resize(id + 1, 0);
  if (cache[id] == 0) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : name) h = (h ^ c) * 1099511628211ull;
    cache[id] = (h ^ 0xff) * 1099511628211ull;
  }
  return cache[id];
}

void Recorder::set_contacts(std::vector<Contact> contacts, std::vector<std::uint32_t> groups) {
  cur_.contacts = std::move(contacts);
  cur_.groups = std::move(groups);
}

bool Recorder::append_task(KindId kind, ObjectId obj, const Access* acc, std::size_t n, std::uint64_t ns) {
  Task t;
  t.kind = kind;
  t.object = obj;
  t.access_begin = static_cast<std::uint32_t>(cur_.accesses.size());
  t.access_count = static_cast<std::uint32_t>(n);
  t.loop = open_loop_;
  cur_.accesses.insert(cur_.accesses.end(), acc, acc + n);
  cur_.tasks.push_back(t);
  cost_sum_.push_back(ns);
  cost_max_.push_back(ns);
  return true;
}

bool Recorder::save_written(const Access* acc, std::size_t n) {
  std::size_t bytes = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!writes(acc[i].mode)) continue;
    if (acc[i].datum >= ptrs_.size() || ptrs_[acc[i].datum] == nullptr) return false;
    bytes += data_[acc[i].datum].bytes;
  }
  saved_.resize(bytes);
  std::size_t at = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!writes(acc[i].mode)) continue;
    const std::size_t b = data_[acc[i].datum].bytes;
    if (b != 0) std::memcpy(saved_.data() + at, ptrs_[acc[i].datum], b);
    at += b;
  }
  return true;
}

void Recorder::restore_written(const Access* acc, std::size_t n) {
  std::size_t at = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!writes(acc[i].mode)) continue;
    const std::size_t b = data_[acc[i].datum].bytes;
    if (b != 0) std::memcpy(ptrs_[acc[i].datum], saved_.data() + at, b);
    at += b;
  }
}

std::uint64_t Recorder::median_ticks() {
  if (pass_ticks_.empty()) return 0;
  const auto mid = pass_ticks_.begin() + static_cast<std::ptrdiff_t>((pass_ticks_.size() - 1) / 2);
  std::nth_element(pass_ticks_.begin(), mid, pass_ticks_.end());
  return *mid;
}

LoopId Recorder::begin_loop(DatumId condition, std::uint32_t max_iterations) {
  if (open_loop_ != kNoLoop) {
    misuse(Call::kBeginLoop,
           "a loop is still open (nested loops are not supported, or its end_loop is missing)",
           open_loop_);
    return open_loop_;
  }
  Loop loop;
  loop.condition = condition;
  loop.first = static_cast<TaskId>(cur_.tasks.size());
  loop.last = loop.first;
  loop.iterations = 0;
  loop.max_iterations = max_iterations;
  cur_.loops.push_back(loop);
  loop_timed_.push_back(0);
  open_loop_ = static_cast<LoopId>(cur_.loops.size() - 1);
  iteration_ = 0;
  time_task_ = true;
  replay_pos_ = 0;
  return open_loop_;
}

bool Recorder::record_break(LoopId loop_id, std::uint64_t ns) {
  if (loop_id != open_loop_ || loop_id == kNoLoop) {
    if (open_loop_ == kNoLoop && loop_id < cur_.loops.size())
      misuse(Call::kConditionalBreak, "the loop was closed by end_loop", loop_id);
    else if (open_loop_ == kNoLoop)
      misuse(Call::kConditionalBreak, "no loop is open (loop id " + std::to_string(loop_id) + ")");
    else
      misuse(Call::kConditionalBreak,
             "loop id " + std::to_string(loop_id) + " is not the open loop", open_loop_);
    return true;
  }
  Loop& loop = cur_.loops[loop_id];
  if (iteration_ == 0) {
    const Access acc{loop.condition, AccessMode::R};
    record(kind("loop.break"), kNoObject, &acc, 1, ns);
    if (mode_ == Mode::kDeferred) bodies_.emplace_back();  // the executor runs conditions[loop]
    loop.last = static_cast<TaskId>(cur_.tasks.size());
    body_first_ = loop.first;
    body_last_ = loop.last;
  } else {
    const TaskId t = loop.first + replay_pos_;
    if (t + 1 != loop.last)
      misuse(Call::kConditionalBreak,
             "iteration " + std::to_string(iteration_) + " issued " + std::to_string(replay_pos_) +
                 " tasks before the break where the first issued " +
                 std::to_string(loop.last - 1 - loop.first),
             loop_id);
    cost_sum_[loop.last - 1] += ns;
    if (ns > cost_max_[loop.last - 1]) cost_max_[loop.last - 1] = ns;
  }
  if (time_task_) ++loop_timed_[loop_id];
  ++iteration_;
  time_task_ = iteration_ < kAlwaysTimed || iteration_ % kTimeEvery == 0;
  replay_pos_ = 0;
  loop.iterations = iteration_;
  return loop.max_iterations != 0 && iteration_ >= loop.max_iterations;
}

void Recorder::end_loop(LoopId loop) {
  if (loop != open_loop_ || loop == kNoLoop) {
    if (open_loop_ == kNoLoop && loop < cur_.loops.size())
      misuse(Call::kEndLoop, "the loop is already closed", loop);
    else if (open_loop_ == kNoLoop)
      misuse(Call::kEndLoop, "no loop is open (loop id " + std::to_string(loop) + ")");
    else
      misuse(Call::kEndLoop, "loop id " + std::to_string(loop) + " is not the open loop",
             open_loop_);
    return;
  }
  if (cur_.loops[loop].iterations == 0)
    misuse(Call::kEndLoop, "no conditional_break was called in the loop", loop);
  open_loop_ = kNoLoop;
  time_task_ = true;
}

StepGraph Recorder::finish_step() {
  if (!in_step_) misuse(Call::kEndStep, "no step was begun (missing begin_step)");
  in_step_ = false;
  if (open_loop_ != kNoLoop) {
    misuse(Call::kEndStep, "the loop is still open (missing end_loop)", open_loop_);
    open_loop_ = kNoLoop;
  }
  if (mode_ == Mode::kOff) return {};
  // Ticks -> ns from the steady_clock duration of the whole step.
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - step_clock_).count();
  const std::uint64_t ticks = detail::ticks() - step_ticks_;
  const double ns_per_tick = ticks == 0 ? 1.0 : static_cast<double>(ns) / static_cast<double>(ticks);
  // Keep the step's buffers' capacity for the next step: the returned graph gets copies.
  StepGraph g;
  g.tasks = cur_.tasks;
  g.accesses = cur_.accesses;
  g.loops = cur_.loops;
  g.contacts = std::move(cur_.contacts);
  g.groups = std::move(cur_.groups);
  g.host_ns = host_ns_;
  g.kinds = kinds_;
  g.objects = objects_;
  g.data = data_;
  // Mean cost per execution; stable key = hash(object name, kind name, occurrence).
  std::unordered_map<std::uint64_t, std::uint32_t> occurrence;
  occurrence.reserve(g.tasks.size());
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    Task& task = g.tasks[t];
    // Timed runs: every run, except for loop body tasks (the break is always timed).
    const LoopId l = task.loop;
    const std::uint64_t runs =
        (l != kNoLoop && t + 1 != g.loops[l].last) ? loop_timed_[l] : g.runs(t);
    // Mean over timed runs; from 3 runs on, the longest one is left out when it is an
    // outlier (over 4x the mean of the others: an OS preemption, not the task's cost).
    const bool trim = runs >= 3 && (cost_sum_[t] - cost_max_[t]) < (cost_max_[t] / 4) * (runs - 1);
    const double sum_ns = static_cast<double>(cost_sum_[t] - (trim ? cost_max_[t] : 0)) * ns_per_tick;
    const double n_runs = static_cast<double>(trim ? runs - 1 : (runs == 0 ? 1 : runs));
    task.cost_ns = static_cast<std::uint64_t>(sum_ns / n_runs + 0.5);
    const std::uint64_t slot = (static_cast<std::uint64_t>(task.object) << 32) | task.kind;
    const std::uint32_t occ = occurrence[slot]++;
    std::uint64_t h = task.object == kNoObject ? 0x9e3779b97f4a7c15ull
                                               : name_hash(object_hash_, task.object, g.objects[task.object].name);
    h = (h ^ name_hash(kind_hash_, task.kind, g.kinds[task.kind])) * 1099511628211ull;
    h = (h ^ occ) * 1099511628211ull;
    task.key = h;
  }
  last_update_ = {};
  if (derive_edges_) {
    if (incremental_edges_) {
      last_update_ = deriver_.derive(g);
    } else {
      const auto t0 = std::chrono::steady_clock::now();
      g.derive_edges();
      last_update_.edges = g.edges.size() + g.carried_edges.size();
      last_update_.ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::steady_clock::now() - t0)
                            .count();
    }
  }
  return g;
}

StepGraph Recorder::end_step() { return finish_step(); }

StepProgram Recorder::end_step_program() {
  StepProgram p;
  p.graph = finish_step();
  p.bodies = std::move(bodies_);
  p.conditions = std::move(conditions_);
  p.accumulators.assign(p.graph.data.size(), nullptr);
  for (std::size_t d = 0; d < accumulators_.size() && d < p.accumulators.size(); ++d)
    p.accumulators[d] = accumulators_[d].get();
  bodies_.clear();
  conditions_.clear();
  return p;
}

}  // namespace tgraph::capture
