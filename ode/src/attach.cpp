// SPDX-License-Identifier: MIT
#include "tgraph/ode/attach.hpp"

#include <ode/threading_impl.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "messages.hpp"
#include "recording.hpp"
#include "runtime.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::ode {
namespace {

using replay::now_ns;  // the steady clock of every timeline

// Every policy but ODE's own stepping runs the calls on tgraph's runtime.
bool runtime_policy(Policy p) { return p != Policy::kOde && p != Policy::kSequential; }

}  // namespace

struct Attachment::Impl {
  dWorldID world = nullptr;
  AttachOptions options;
  unsigned previous_island_threads = 1;
  std::unique_ptr<detail::Runtime> runtime;
  dThreadingImplementationID ode_impl = nullptr;
  dThreadingThreadPoolID ode_pool = nullptr;
  std::unique_ptr<partition::Strategy> strategy;
  std::vector<detail::StepLog> logs;  // options.record
  RecordingRoom room;                 // the largest recorded step's
  std::int64_t pending_host_ns = 0;
  std::uint64_t messages_at_start = 0;
  AttachStats stats;
};

Attachment::Attachment(dWorldID world, const AttachOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (options.threads == 0) throw OptionError("threads", "must be at least 1");
  if (world == nullptr) throw OptionError("world", "no ODE world to attach to (null dWorldID)");
  const Policy policy = options.method.policy;
  if (options.record && !runtime_policy(policy))
    throw OptionError(
        "method",
        "recording needs tgraph's runtime (worksteal, islands, islands-serial or a partition "
        "strategy): under '" +
            std::string(to_string(policy)) + "' ODE runs its calls where tgraph cannot see them");
  if (policy == Policy::kPartition)
    impl_->strategy = partition::make_strategy(options.method.strategy);
  impl_->world = world;
  impl_->options = options;
  if (options.handle_messages) detail::acquire_message_handlers();
  impl_->messages_at_start = detail::message_count();
  impl_->previous_island_threads = dWorldGetStepIslandsProcessingMaxThreadCount(world);
  switch (policy) {
    case Policy::kSequential:
      dWorldSetStepThreadingImplementation(world, nullptr, nullptr);  // ODE self-threaded
      break;
    case Policy::kOde:
      // As ODE ships it: its implementation served by its pool of K threads; the stepping
      // thread waits inside wait_call.
      impl_->ode_impl = dThreadingAllocateMultiThreadedImplementation();
      impl_->ode_pool =
          dThreadingAllocateThreadPool(options.threads, 0, dAllocateFlagBasicData, nullptr);
      if (!impl_->ode_impl || !impl_->ode_pool)
        throw std::runtime_error("ODE could not allocate its threading implementation or pool");
      dThreadingThreadPoolServeMultiThreadedImplementation(impl_->ode_pool, impl_->ode_impl);
      dWorldSetStepThreadingImplementation(
          world, dThreadingImplementationGetFunctions(impl_->ode_impl), impl_->ode_impl);
      break;
    case Policy::kWorksteal:
    case Policy::kIslands:
    case Policy::kIslandsSerial:
    case Policy::kPartition: {
      detail::RuntimeOptions ro;
      ro.threads = options.threads;
      ro.placed = policy == Policy::kPartition;
      ro.steal_root_only = policy == Policy::kIslands;
      ro.serial_islands = policy == Policy::kIslandsSerial;
      ro.spin_ns = options.spin_ns;
      ro.watchdog_s = options.watchdog_s;
      impl_->runtime = std::make_unique<detail::Runtime>(ro);
      reserve_recording(options.reserve_steps);
      dWorldSetStepThreadingImplementation(world, impl_->runtime->functions(),
                                           impl_->runtime->id());
      break;
    }
  }
  dWorldSetStepIslandsProcessingMaxThreadCount(world, options.threads);
}

Attachment::~Attachment() {
  Impl& m = *impl_;
  // First the world lets go of what it allocated through the implementation (ODE frees it
  // through the old one), then the implementation goes.
  dWorldSetStepThreadingImplementation(m.world, nullptr, nullptr);
  dWorldSetStepIslandsProcessingMaxThreadCount(m.world, m.previous_island_threads);
  if (m.ode_impl) {
    dThreadingImplementationShutdownProcessing(m.ode_impl);
    dThreadingFreeThreadPool(m.ode_pool);
    dThreadingFreeImplementation(m.ode_impl);
  }
  m.runtime.reset();
  if (m.options.handle_messages) detail::release_message_handlers();
}

void Attachment::quick_step(dReal dt) { world_step(Stepper::kQuickStep, dt); }
void Attachment::step(dReal dt) { world_step(Stepper::kStep, dt); }

void Attachment::world_step(Stepper stepper, dReal dt) {
  Impl& m = *impl_;
  const char* entry = stepper == Stepper::kQuickStep ? "dWorldQuickStep" : "dWorldStep";
  detail::Runtime* rt = m.runtime.get();
  const bool partition_point =
      m.strategy && m.stats.steps % std::max<std::uint32_t>(m.options.repartition_interval, 1) == 0;
  const bool record = rt && (m.options.record || partition_point);
  std::uint64_t calls_before = 0, refused_before = 0;
  if (rt) {
    calls_before = rt->counters().calls;
    refused_before = rt->serial_islands_refused();
    rt->set_recording(record);
    rt->begin_step(entry);
  }
  const std::int64_t t0 = now_ns();
  const int ok =
      stepper == Stepper::kQuickStep ? dWorldQuickStep(m.world, dt) : dWorldStep(m.world, dt);
  const std::int64_t t1 = now_ns();
  detail::StepLog log;
  if (rt) log = rt->end_step();
  m.stats.world_ns += t1 - t0;
  ++m.stats.steps;
  if (!ok)
    throw std::runtime_error(std::string(entry) +
                             " failed (ODE could not allocate its step's memory)");
  if (rt && rt->counters().calls == calls_before)
    throw UsageError(
        std::string(entry) +
        " posted no call to tgraph's threading: the world is "
        "not stepped through this attachment (was dWorldSetStepThreadingImplementation "
        "called after attaching?)");
  if (rt && rt->serial_islands_refused() != refused_before)
    throw UsageError(std::string(entry) +
                     " did not plan its step as ODE 0.16.2 does (two thread-count queries, "
                     "then its island jobs): islands-serial needs ODE 0.16.2's step; this "
                     "step ran as ODE planned it");
  if (record) {
    log.entry = entry;
    log.host_ns = m.pending_host_ns;
  }
  m.pending_host_ns = 0;
  if (partition_point) {
    // The step just recorded, partitioned: its calls' placement for the next steps.
    const std::int64_t p0 = now_ns();
    const StepGraph g = detail::build_step_graph(log);
    const partition::Result r = m.strategy->partition(g, m.options.threads, {}, m.options.strategy);
    std::unordered_map<std::uint64_t, std::uint32_t> placement;
    placement.reserve(g.tasks.size());
    for (TaskId t = 0; t < g.tasks.size(); ++t)
      placement.emplace(g.tasks[t].key, r.assignment.proc[t]);
    rt->set_placement(std::move(placement));
    m.stats.partition_ns += now_ns() - p0;
    ++m.stats.partitions;
  }
  if (m.options.record) {
    RecordingRoom& r = m.room;  // the largest step's and thread's so far
    std::size_t parts = 0, relations = 0, calls = 0;
    for (const detail::SlotLog& part : log.slots) {
      parts += part.segments.size();
      relations += part.accesses.size();
      calls += part.calls.size();
      r.thread_parts = std::max(r.thread_parts, part.segments.size());
      r.thread_relations = std::max(r.thread_relations, part.accesses.size());
      r.thread_calls = std::max(r.thread_calls, part.calls.size());
    }
    r.parts = std::max(r.parts, parts);
    r.relations = std::max(r.relations, relations);
    r.calls = std::max(r.calls, calls);
    m.logs.push_back(std::move(log));
  }
}

void Attachment::collide(dSpaceID space, void* data, dNearCallback* callback) {
  const std::int64_t t0 = now_ns();
  dSpaceCollide(space, data, callback);
  const std::int64_t dt = now_ns() - t0;
  impl_->pending_host_ns += dt;
  impl_->stats.collide_ns += dt;
}

std::vector<StepGraph> Attachment::take_steps() {
  std::vector<StepGraph> steps;
  steps.reserve(impl_->logs.size());
  for (const detail::StepLog& log : impl_->logs) steps.push_back(detail::build_step_graph(log));
  impl_->logs.clear();
  return steps;
}

void Attachment::drop_steps() { impl_->logs.clear(); }

RecordingRoom Attachment::recording_room() const { return impl_->room; }

void Attachment::reserve_recording(std::uint32_t steps) {
  if (!impl_->options.record || !impl_->runtime || steps == 0) return;
  // Each thread: twice its largest share, at most the whole step, and 10 % more.
  const RecordingRoom& r = impl_->options.reserve_room;
  const auto room = [](std::size_t whole, std::size_t thread) {
    const std::size_t n = std::min(whole, 2 * thread);
    return n + n / 10 + 16;
  };
  impl_->runtime->reserve_logs(steps, room(r.parts, r.thread_parts),
                               room(r.relations, r.thread_relations),
                               room(r.calls, r.thread_calls));
}

AttachStats Attachment::stats() const {
  AttachStats s = impl_->stats;
  if (impl_->runtime) {
    const detail::RuntimeCounters c = impl_->runtime->counters();
    s.calls = c.calls;
    s.steals = c.steals;
    s.parks = c.parks;
  }
  s.messages = detail::message_count() - impl_->messages_at_start;
  if (s.messages) s.first_message = detail::first_message();
  return s;
}

const AttachOptions& Attachment::options() const { return impl_->options; }
dWorldID Attachment::world() const { return impl_->world; }

}  // namespace tgraph::ode
