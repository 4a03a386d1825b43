// SPDX-License-Identifier: MIT
// The calling thread's binding to a core, for code that times work outside an executor on
// the cores the executor's threads use (the uninstrumented engine of a live run).
#pragma once

#include <memory>

namespace tgraph::replay {

/// Saves the calling thread's binding; pin() binds it to thread slot p's processing unit (as
/// the executors pin thread p); the destructor restores the saved binding.
///
///   { BindingScope b; b.pin(1); run(); }  // on thread 1's core, then back
class BindingScope {
 public:
  BindingScope();
  ~BindingScope();
  BindingScope(const BindingScope&) = delete;
  BindingScope& operator=(const BindingScope&) = delete;
  /// False if hwloc cannot bind (never fails the run).
  bool pin(unsigned p);

 private:
  struct Saved;
  std::unique_ptr<Saved> saved_;
};

/// Number of processing units (hwloc; the hardware concurrency without it).
unsigned hardware_pus();

}  // namespace tgraph::replay
