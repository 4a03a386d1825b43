// SPDX-License-Identifier: MIT
// An existing ODE world stepped through tgraph: ODE's threading interface implemented on
// tgraph's threads (or ODE's own pool, or nothing: ODE self-threaded), each step's calls
// recorded as a task graph on request (docs/ode.md).
#pragma once

#include <ode/ode.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tgraph/graph/step_graph.hpp"
#include "tgraph/ode/method.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::ode {

/// Room for a step's recording, in records (Attachment::recording_room()).
struct RecordingRoom {
  std::size_t parts = 0, relations = 0, calls = 0;  ///< the largest step's, all threads
  std::size_t thread_parts = 0, thread_relations = 0, thread_calls = 0;  ///< one thread's largest
};

/// What an attachment does.
struct AttachOptions {
  Method method;              ///< who runs ODE's calls
  std::uint32_t threads = 2;  ///< K: the stepping thread and K - 1 workers (at least 1)
  /// Record every step's calls (steps()): the runtime's policies only (worksteal, partition).
  bool record = false;
  /// Recording: room for this many steps of `reserve_room` made and written once when
  /// attaching, so that the recorded steps do not fault their logs' fresh pages in while they
  /// run (a capture sizes it from an untimed first pass). Each thread gets twice its largest
  /// share, at most the whole step, and 10 % more; a step that needs more grows its log.
  std::uint32_t reserve_steps = 0;
  RecordingRoom reserve_room{};
  /// Partition policy: steps between two partitionings of the last recorded step (the first
  /// step is recorded and partitioned for the second; then every `repartition_interval`).
  std::uint32_t repartition_interval = 10;
  partition::Options strategy;  ///< the partition policy's strategy options
  /// A thread without work spins this long before it parks (ns).
  std::int64_t spin_ns = 50'000;
  /// A call running longer than this (seconds) stops the program with one line naming it
  /// (exit 1); 0: no watchdog.
  double watchdog_s = 60.0;
  /// Route dError, dDebug and dMessage to one line on stderr (exit 1 for the first two)
  /// instead of ODE's default abort.
  bool handle_messages = true;
};

/// What an attachment measured.
struct AttachStats {
  std::uint64_t steps = 0;
  std::int64_t world_ns = 0;      ///< in the world step (dWorldQuickStep / dWorldStep)
  std::int64_t collide_ns = 0;    ///< in collide(): the host's serial part
  std::int64_t partition_ns = 0;  ///< partition policy: graphs built and partitioned
  std::uint64_t partitions = 0;   ///< partition policy: steps whose graph was partitioned
  std::uint64_t calls = 0;        ///< calls ODE posted (the runtime's policies)
  std::uint64_t steals = 0;       ///< calls run by a thread other than the one they were placed on
  std::uint64_t parks = 0;        ///< times a thread parked
  std::uint64_t messages = 0;     ///< dMessage warnings seen (ODE's "LCP internal error"...)
  std::string first_message;      ///< the first of them
};

/// `world` attached to tgraph's threading for as long as this object lives: ODE's calls run
/// on `options.threads` threads under `options.method`; the step and collision functions
/// below time (and record) each step. Detaching restores ODE self-threaded stepping.
///
///   tgraph::ode::Attachment attach(world, {.method = {tgraph::ode::Policy::kWorksteal},
///                                          .threads = 2});
///   for (...) {
///     attach.collide(space, nullptr, &near_callback);   // dSpaceCollide, timed
///     attach.quick_step(0.005);                          // dWorldQuickStep on 2 threads
///     dJointGroupEmpty(contacts);
///   }
class Attachment {
 public:
  /// OptionError for 0 threads, a null world, or recording under a policy that cannot.
  Attachment(dWorldID world, const AttachOptions& options);
  ~Attachment();
  Attachment(const Attachment&) = delete;
  Attachment& operator=(const Attachment&) = delete;

  /// dWorldQuickStep(world, dt) through the attachment (timed, recorded when asked).
  void quick_step(dReal dt);
  /// dWorldStep(world, dt) through the attachment.
  void step(dReal dt);
  /// quick_step or step.
  void world_step(Stepper stepper, dReal dt);
  /// dSpaceCollide(space, data, callback), timed as the next step's host work.
  void collide(dSpaceID space, void* data, dNearCallback* callback);

  /// The recorded steps so far, as task graphs (edges derived); empties the record.
  std::vector<StepGraph> take_steps();
  /// Empties the record without building its graphs (recording_room() keeps its maxima).
  void drop_steps();
  /// The largest step recorded so far (AttachOptions::reserve_room).
  RecordingRoom recording_room() const;
  /// Recording: room for the next `steps` steps of `options().reserve_room`, made and written
  /// now, between steps, as AttachOptions::reserve_steps does when attaching (a long recording
  /// taken in parts: take_steps, then room for the next part).
  void reserve_recording(std::uint32_t steps);
  /// What was measured so far.
  AttachStats stats() const;
  const AttachOptions& options() const;
  dWorldID world() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tgraph::ode
