// SPDX-License-Identifier: MIT
// The SimGrid engine of `tgraph simulate`: every step of a trace as SimGrid s4u activities
// (one Exec per task instance on its processor's host, one Comm per datum version and
// receiving processor on the platform's links), created when they become ready.
//
// The process that hosts it (one engine per process) is simgrid_process.cpp.
#include "simgrid_engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <simgrid/s4u.hpp>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "schedule_program.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/model/simulation.hpp"

namespace tgraph::model::detail {

namespace {

namespace sg = simgrid::s4u;

/// When a finished instance (task t, iteration i) sends to a processor: every iteration
/// (same loop body), all but the last (loop-carried edge to iteration i + 1), or only the
/// last run (a reader after the loop, or outside any loop).
enum class When : std::uint8_t { every, not_last, last };

/// One outgoing dependency of a task towards another processor.
struct Out {
  ProcId to;
  DatumId datum;
  bool raw;
  When when;
  bool decision = false;  ///< a loop's break decision (datum: the loop's condition)
};

enum class Kind : std::uint8_t { host, exec, comm };

/// An activity in flight and what its completion means.
struct InFlight {
  sg::ActivityPtr activity;
  Kind kind;
  TaskId task;
  std::uint32_t iteration;
  ProcId proc;                    ///< exec: where it runs; comm: the sender
  std::vector<ProcId> receivers;  ///< comm: the processors that know the instance on arrival
  std::uint32_t messages = 0;     ///< comm between nodes: the MPI messages it stands for
};

/// Runs the steps of a trace one after the other on the given hosts (host of processor p);
/// `read_ns_per_byte[p]`: what reading a byte written by another core of its node costs
/// processor p (its host's loopback link) when the reader pays for transfers in a node;
/// `overhead_ns`: the runtime's own time per task instance (CostModel::task_overhead_ns);
/// `message_ns`: the processor time of one MPI message between nodes on each side
/// (CostModel::mpi_message_overhead_ns).
class Driver {
 public:
  Driver(const Trace& trace, const TraceAssignment& a, std::vector<sg::Host*> hosts,
         std::vector<double> read_ns_per_byte, IntraNodeTransfer intra_node, double overhead_ns,
         double message_ns)
      : trace_(trace),
        a_(a),
        hosts_(std::move(hosts)),
        read_ns_per_byte_(std::move(read_ns_per_byte)),
        overhead_(static_cast<std::uint64_t>(std::llround(overhead_ns))),
        message_(static_cast<std::uint64_t>(std::llround(message_ns))),
        reader_pays_(intra_node == IntraNodeTransfer::reader),
        steps_(std::min(trace.steps.size(), a.steps.size())) {}

  /// Starts step 0; the engine's run() does the rest through on_completion().
  void start() {
    begin_step(0);
    while (step_ < steps_ && finished_ == k_ && outstanding_ == 0) end_step();
  }

  void on_completion(const sg::Activity& activity) {
    const auto found = live_.find(&activity);
    if (found == live_.end()) return;
    InFlight f = std::move(found->second);
    // The engine still uses the activity after this callback: keep it alive until the
    // clock moves on (on_time_advance()).
    graveyard_.push_back(f.activity);
    live_.erase(found);
    --outstanding_;
    switch (f.kind) {
      case Kind::host:
        for (ProcId p = 0; p < k_; ++p) wake_proc(p);
        break;
      case Kind::exec:
        state_[f.proc].running = false;
        step_forward(f.proc);
        finish_instance(f.task, f.iteration, f.proc);
        wake_proc(f.proc);
        break;
      case Kind::comm:
        // The receiving rank's time for the messages (one thread of it: the first receiver)
        // goes before that processor's next instance, where the MPI replay polls for them.
        pending_[f.receivers.front()] += message_ * f.messages;
        for (ProcId q : f.receivers) {
          const std::uint64_t key = (first_[f.task] + f.iteration) * k_ + q;
          arrived_.insert(key);
          wake(key);
        }
        break;
    }
    drain();
    while (step_ < steps_ && finished_ == k_ && outstanding_ == 0) end_step();
  }

  void on_time_advance() { graveyard_.clear(); }

  bool done() const { return step_ >= steps_; }
  const std::vector<StepPrediction>& results() const { return results_; }

  /// Why the simulation stopped before the end (a processor that waits forever).
  std::string stuck() const {
    for (ProcId p = 0; p < k_; ++p)
      if (!state_[p].finished)
        return "step " + std::to_string(step_) + ": " +
               deadlock_message(*g_, items_[p][state_[p].item], state_[p].pos, p);
    return "step " + std::to_string(step_) + ": the simulation stopped early";
  }

 private:
  struct State {
    std::size_t item = 0;
    std::uint32_t iter = 0;
    std::size_t pos = 0;
    bool running = false;
    bool finished = false;
    bool queued = false;
  };

  void begin_step(std::size_t s) {
    step_ = s;
    if (s >= steps_) return;
    g_ = &trace_.steps[s];
    pa_ = &a_.steps[s];
    k_ = pa_->k;
    first_ = first_instances(*g_);
    deps_ = dependencies(*g_);
    items_ = programs(*g_, *pa_);
    build_outs();
    done_.assign(first_.back(), 0);
    arrived_.clear();
    received_.clear();
    waiters_.clear();
    state_.assign(k_, State{});
    pending_.assign(k_, 0);
    finished_ = 0;
    current_ = {};
    start_ = sg::Engine::get_clock();
    // The step's serial host work (StepGraph::host_ns) runs on processor 0's core before
    // any task, as in the built-in simulator.
    if (g_->host_ns > 0) {
      sg::ExecPtr x = sg::Exec::init();
      x->set_flops_amount(static_cast<double>(g_->host_ns));
      x->set_host(hosts_[0]);
      track(x, Kind::host, kNoTask, 0, 0);
      x->start();
    } else {
      for (ProcId p = 0; p < k_; ++p) wake_proc(p);
      drain();
    }
  }

  void end_step() {
    current_.makespan_ns =
        static_cast<std::uint64_t>(std::llround((sg::Engine::get_clock() - start_) * 1e9));
    results_.push_back(current_);
    begin_step(step_ + 1);
  }

  // Per task, its dependencies towards other processors (and, for a loop's break task, the
  // decision every other processor running part of the body waits for), by receiver.
  void build_outs() {
    const auto n = static_cast<TaskId>(g_->tasks.size());
    outs_.assign(n, {});
    for (TaskId u = 0; u < n; ++u) {
      const ProcId pu = pa_->proc[u];
      const LoopId lu = g_->tasks[u].loop;
      for (const Dep& d : deps_[u]) {
        if (pa_->proc[d.from] == pu) continue;
        const LoopId lf = g_->tasks[d.from].loop;
        const When when = d.carried                   ? When::not_last
                          : lf != kNoLoop && lf == lu ? When::every
                                                      : When::last;
        if (g_->runs(u) == 0) continue;  // a reader that never runs waits for nothing
        outs_[d.from].push_back({pu, d.datum, d.raw, when});
      }
    }
    for (LoopId l = 0; l < g_->loops.size(); ++l) {
      const Loop& loop = g_->loops[l];
      if (loop.iterations == 0) continue;
      const TaskId brk = loop.last - 1;
      for (ProcId p = 0; p < k_; ++p) {
        if (p == pa_->proc[brk]) continue;
        const bool holds = std::any_of(items_[p].begin(), items_[p].end(),
                                       [&](const Item& it) { return it.loop == l; });
        if (holds) outs_[brk].push_back({p, loop.condition, false, When::every, true});
      }
    }
    for (auto& o : outs_)
      std::stable_sort(o.begin(), o.end(), [](const Out& x, const Out& y) { return x.to < y.to; });
  }

  void track(const sg::ActivityPtr& act, Kind kind, TaskId t, std::uint32_t i, ProcId p) {
    live_.emplace(act.get(), InFlight{act, kind, t, i, p, {}});
    ++outstanding_;
  }

  void wake_proc(ProcId p) {
    if (state_[p].queued) return;
    state_[p].queued = true;
    ready_.push_back(p);
  }

  void wake(std::uint64_t key) {
    const auto w = waiters_.find(key);
    if (w == waiters_.end()) return;
    for (ProcId p : w->second) wake_proc(p);
    waiters_.erase(w);
  }

  void drain() {
    while (!ready_.empty()) {
      const ProcId p = ready_.front();
      ready_.pop_front();
      state_[p].queued = false;
      advance(p);
    }
  }

  // Whether instance `inst` (run on processor `owner`) is known on processor p: finished
  // when local, its transfer arrived when not. Registers p as a waiter when not.
  bool known(std::uint64_t inst, ProcId owner, ProcId p) {
    const std::uint64_t key = inst * k_ + p;
    if (owner == p ? done_[inst] != 0 : arrived_.count(key) != 0) return true;
    waiters_[key].push_back(p);
    return false;
  }

  bool ready(ProcId p, TaskId t, std::uint32_t i) {
    for (const Dep& d : deps_[t]) {
      const std::uint64_t src = dependency_source(*g_, first_, d, t, i);
      if (src != kNoInstance && !known(src, pa_->proc[d.from], p)) return false;
    }
    return true;
  }

  // Inside a node, when the reader pays: the bytes of the datum versions task t (iteration
  // i) is the first on p to receive, at p's loopback cost per byte (the built-in
  // simulator's rule: once per version and processor, reads only).
  std::uint64_t read_cost(ProcId p, TaskId t, std::uint32_t i) {
    if (!reader_pays_) return 0;
    std::uint64_t bytes = 0;
    for (const Dep& d : deps_[t]) {
      const ProcId from = pa_->proc[d.from];
      if (from == p || hosts_[from] != hosts_[p]) continue;
      const std::uint64_t src = dependency_source(*g_, first_, d, t, i);
      if (src == kNoInstance) continue;
      if (received_.insert({src, d.datum, p}) && d.raw) bytes += g_->data[d.datum].bytes;
    }
    current_.bytes += bytes;
    return static_cast<std::uint64_t>(
        std::llround(static_cast<double>(bytes) * read_ns_per_byte_[p]));
  }

  void step_forward(ProcId p) {
    State& st = state_[p];
    if (items_[p][st.item].task != kNoTask)
      ++st.item;
    else
      ++st.pos;
  }

  // Runs processor p as far as it can without waiting for the simulated time to move.
  void advance(ProcId p) {
    State& st = state_[p];
    if (st.running || st.finished) return;
    while (st.item < items_[p].size()) {
      const Item& it = items_[p][st.item];
      const bool loop_task =
          it.task == kNoTask && g_->loops[it.loop].iterations > 0 && st.pos < it.body.size();
      if (it.task != kNoTask || loop_task) {
        const TaskId t = it.task != kNoTask ? it.task : it.body[st.pos];
        const std::uint32_t i = it.task != kNoTask ? 0 : st.iter;
        if (!ready(p, t, i)) return;
        const std::uint64_t cost = g_->tasks[t].cost_ns + overhead_ + read_cost(p, t, i) +
                                   send_cost(t, i, p) + std::exchange(pending_[p], 0);
        if (cost == 0) {  // nothing to simulate: it finishes when it starts
          step_forward(p);
          finish_instance(t, i, p);
          continue;
        }
        sg::ExecPtr x = sg::Exec::init();
        x->set_flops_amount(static_cast<double>(cost));
        x->set_host(hosts_[p]);
        track(x, Kind::exec, t, i, p);
        st.running = true;
        x->start();
        return;
      }
      const Loop& loop = g_->loops[it.loop];
      if (loop.iterations == 0) {
        ++st.item;
        continue;
      }
      // End of an iteration: loop control needs the break task's decision (section 3.3).
      const TaskId brk = loop.last - 1;
      if (!known(first_[brk] + st.iter, pa_->proc[brk], p)) return;
      st.pos = 0;
      if (++st.iter == loop.iterations) {
        st.iter = 0;
        ++st.item;
      }
    }
    st.finished = true;
    ++finished_;
  }

  // Instance (t, i) finished on processor `owner`: its local readers may go on, and its
  // data (and loop decision) leave for every other processor that reads them.
  void finish_instance(TaskId t, std::uint32_t i, ProcId owner) {
    const std::uint64_t inst = first_[t] + i;
    done_[inst] = 1;
    wake(inst * k_ + owner);
    for_each_transfer(t, i, owner, [&](std::uint64_t bytes, std::uint32_t messages) {
      // The reader pays for the bytes inside a node (read_cost): the link carries the signal.
      const bool in_node = hosts_[owner] == hosts_[receivers_.front()];
      send(t, i, owner, reader_pays_ && in_node ? 0 : bytes, in_node ? 0 : messages);
    });
  }

  // The sending processor's time for the MPI messages instance (t, i) sends to other nodes
  // once it has run (charged to the instance itself).
  std::uint64_t send_cost(TaskId t, std::uint32_t i, ProcId owner) {
    if (message_ == 0) return 0;
    std::uint64_t messages = 0;
    for_each_transfer(t, i, owner, [&](std::uint64_t, std::uint32_t m) {
      if (hosts_[owner] != hosts_[receivers_.front()]) messages += m;
    });
    return messages * message_;
  }

  // Calls fn(bytes, messages) for each transfer instance (t, i), run on `owner`, makes once
  // it has run, with receivers_ set to its receivers: one transfer per receiver in the
  // owner's node, one per other node. `messages`: what the MPI replay sends for it, one per
  // datum version and one per loop decision (a dependency that carries no value is no
  // message).
  template <class Fn>
  void for_each_transfer(TaskId t, std::uint32_t i, ProcId owner, Fn&& fn) {
    const std::uint64_t runs = g_->runs(t);
    const std::vector<Out>& outs = outs_[t];
    // Outs are sorted by processor, a node's processors contiguous.
    auto same_group = [&](const Out& x, const Out& y) {
      return hosts_[x.to] == hosts_[owner] ? x.to == y.to : hosts_[x.to] == hosts_[y.to];
    };
    for (std::size_t b = 0; b < outs.size();) {
      std::size_t e = b;
      std::uint64_t bytes = 0;
      std::uint32_t decisions = 0;
      sent_.clear();
      receivers_.clear();
      for (; e < outs.size() && same_group(outs[e], outs[b]); ++e) {
        const Out& o = outs[e];
        const bool applies =
            o.when == When::every || (o.when == When::not_last ? i + 1 < runs : i + 1 == runs);
        if (!applies) continue;
        if (receivers_.empty() || receivers_.back() != o.to) receivers_.push_back(o.to);
        decisions = std::max<std::uint32_t>(decisions, o.decision ? 1 : 0);
        // Each datum version is sent once per receiving processor or node (reads only).
        if (o.raw && std::find(sent_.begin(), sent_.end(), o.datum) == sent_.end()) {
          sent_.push_back(o.datum);
          bytes += g_->data[o.datum].bytes;
        }
      }
      if (!receivers_.empty()) fn(bytes, static_cast<std::uint32_t>(sent_.size()) + decisions);
      b = e;
    }
  }

  // One transfer of instance (t, i) from processor `from` to receivers_ (one node).
  void send(TaskId t, std::uint32_t i, ProcId from, std::uint64_t bytes, std::uint32_t messages) {
    const ProcId to = receivers_.front();
    sg::CommPtr c = sg::Comm::sendto_init(hosts_[from], hosts_[to]);
    c->set_payload_size(bytes);
    live_.emplace(c.get(), InFlight{c, Kind::comm, t, i, from, receivers_, messages});
    ++outstanding_;
    ++current_.messages;
    current_.bytes += bytes;
    if (hosts_[from] != hosts_[to]) {
      ++current_.inter_node_messages;
      current_.inter_node_bytes += bytes;
    }
    c->start();
  }

  const Trace& trace_;
  const TraceAssignment& a_;
  const std::vector<sg::Host*> hosts_;
  const std::vector<double> read_ns_per_byte_;
  const std::uint64_t overhead_;
  const std::uint64_t message_;
  const bool reader_pays_;
  const std::size_t steps_;
  std::size_t step_ = 0;
  const StepGraph* g_ = nullptr;
  const Assignment* pa_ = nullptr;
  std::uint64_t k_ = 1;
  std::vector<std::uint64_t> first_;
  std::vector<std::vector<Dep>> deps_;
  std::vector<std::vector<Item>> items_;
  std::vector<std::vector<Out>> outs_;
  std::vector<std::uint8_t> done_;
  std::unordered_set<std::uint64_t> arrived_;
  VersionSet received_;  // the reader paid
  std::unordered_map<std::uint64_t, std::vector<ProcId>> waiters_;
  std::vector<State> state_;
  std::vector<std::uint64_t> pending_;  // received messages' time, before p's next instance
  std::deque<ProcId> ready_;
  std::vector<DatumId> sent_;
  std::vector<ProcId> receivers_;
  std::uint32_t finished_ = 0;
  std::uint64_t outstanding_ = 0;
  double start_ = 0;
  StepPrediction current_;
  std::vector<StepPrediction> results_;
  std::unordered_map<const sg::Activity*, InFlight> live_;
  std::vector<sg::ActivityPtr> graveyard_;
};

// Host names compared as text with digit runs compared as numbers (node-2 < node-10).
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool db = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (da && db) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const std::string na = a.substr(i, ie - i), nb = b.substr(j, je - j);
      const auto za = na.find_first_not_of('0'), zb = nb.find_first_not_of('0');
      const std::string ta = za == std::string::npos ? "" : na.substr(za);
      const std::string tb = zb == std::string::npos ? "" : nb.substr(zb);
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace

PlatformRun run_on_loaded_platform(const Trace& trace, const TraceAssignment& a,
                                   const SimulatedPlatform& platform) {
  PlatformRun out;
  std::vector<sg::Host*> all = sg::Engine::get_instance()->get_all_hosts();
  std::sort(all.begin(), all.end(), [](const sg::Host* x, const sg::Host* y) {
    return natural_less(x->get_name(), y->get_name());
  });
  std::vector<sg::Host*> proc_hosts;
  std::uint64_t cores = 0;
  for (sg::Host* h : all) {
    const int c = h->get_core_count();
    cores += static_cast<std::uint64_t>(std::max(c, 0));
    for (int i = 0; i < c && proc_hosts.size() < a.k; ++i) proc_hosts.push_back(h);
  }
  if (proc_hosts.size() < a.k) {
    out.input_error = "the assignment has " + std::to_string(a.k) + " processors, the platform " +
                      (platform.file.empty() ? std::string("cluster") : platform.file) + " only " +
                      std::to_string(cores) + " cores on " + std::to_string(all.size()) + " hosts";
    return out;
  }
  // A host's loopback link (its route to itself) prices a byte read from another core.
  std::vector<double> read_ns_per_byte;
  for (const sg::Host* h : proc_hosts) {
    std::vector<sg::Link*> links;
    double latency = 0;
    h->route_to(h, links, &latency);
    double bandwidth = 0;
    for (const sg::Link* l : links)
      bandwidth = bandwidth == 0 ? l->get_bandwidth() : std::min(bandwidth, l->get_bandwidth());
    read_ns_per_byte.push_back(bandwidth > 0 ? 1e9 / bandwidth : 0.0);
  }
  Driver driver(trace, a, proc_hosts, std::move(read_ns_per_byte), platform.intra_node,
                platform.model.task_overhead_ns, platform.model.mpi_message_overhead_ns);
  sg::Activity::on_completion_cb([&](const sg::Activity& act) { driver.on_completion(act); });
  sg::Engine::on_time_advance_cb([&](double) { driver.on_time_advance(); });
  driver.start();
  sg::Engine::get_instance()->run();
  if (!driver.done()) {
    out.input_error = driver.stuck();
    return out;
  }
  out.hosts = all.size();
  out.cores = cores;
  out.steps = driver.results();
  return out;
}

}  // namespace tgraph::model::detail
