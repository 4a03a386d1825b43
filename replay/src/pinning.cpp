// SPDX-License-Identifier: MIT
// Thread pinning with hwloc: thread p -> p-th PU in "one PU per core first" order.
#include <hwloc.h>

#include <mutex>
#include <thread>
#include <vector>

#include "pinning.hpp"
#include "sync.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::replay {
namespace detail {
namespace {

struct Topology {
  hwloc_topology_t topo = nullptr;
  std::vector<hwloc_obj_t> order;  // PUs: first PU of each core, then the others
  Topology() {
    if (hwloc_topology_init(&topo) != 0) return;
    if (hwloc_topology_load(topo) != 0) {
      hwloc_topology_destroy(topo);
      topo = nullptr;
      return;
    }
    const int cores = hwloc_get_nbobjs_by_type(topo, HWLOC_OBJ_CORE);
    int depth = 0;
    for (;; ++depth) {
      bool any = false;
      for (int c = 0; c < cores; ++c) {
        hwloc_obj_t core = hwloc_get_obj_by_type(topo, HWLOC_OBJ_CORE, static_cast<unsigned>(c));
        hwloc_obj_t pu = hwloc_get_obj_inside_cpuset_by_type(topo, core->cpuset, HWLOC_OBJ_PU,
                                                             static_cast<unsigned>(depth));
        if (pu) {
          order.push_back(pu);
          any = true;
        }
      }
      if (!any) break;
    }
    if (order.empty()) {
      const int pus = hwloc_get_nbobjs_by_type(topo, HWLOC_OBJ_PU);
      for (int i = 0; i < pus; ++i)
        order.push_back(hwloc_get_obj_by_type(topo, HWLOC_OBJ_PU, static_cast<unsigned>(i)));
    }
  }
};

// Never destroyed: oneTBB's worker threads outlive static destruction and may still enter an
// arena (and bind themselves) while the process exits.
Topology& topology() {
  static Topology* t = new Topology;
  return *t;
}

/// The calling thread's binding by the rule: the slot whose PU it is bound to, or -1.
thread_local std::int64_t t_bound_slot = -1;

}  // namespace

std::mutex& hwloc_mutex() {
  static std::mutex m;
  return m;
}

bool pin_current_thread(std::uint32_t p) {
  Topology& t = topology();
  t_bound_slot = -1;
  if (!t.topo || t.order.empty()) return false;
  // No lock: binding reads the loaded topology only, which hwloc allows from any thread.
  hwloc_obj_t pu = t.order[p % t.order.size()];
  if (hwloc_set_cpubind(t.topo, pu->cpuset, HWLOC_CPUBIND_THREAD) != 0) return false;
  t_bound_slot = p;
  return true;
}

bool bind_current_thread(bool pin, std::uint32_t slot) {
  if (pin) return t_bound_slot == static_cast<std::int64_t>(slot) || pin_current_thread(slot);
  if (t_bound_slot < 0) return true;
  Topology& t = topology();
  t_bound_slot = -1;
  if (!t.topo) return false;
  // Back to every PU the process may use (a binding an earlier executor left).
  return hwloc_set_cpubind(t.topo, hwloc_topology_get_allowed_cpuset(t.topo),
                           HWLOC_CPUBIND_THREAD) == 0;
}

std::int64_t bound_slot() { return t_bound_slot; }

int pinned_pu_logical(std::uint32_t p) {
  Topology& t = topology();
  if (!t.topo || t.order.empty()) return -1;
  return static_cast<int>(t.order[p % t.order.size()]->logical_index);
}

void save_binding(SavedBinding& s) {
  Topology& t = topology();
  if (!t.topo) return;
  std::lock_guard<std::mutex> lock(hwloc_mutex());
  hwloc_bitmap_t set = hwloc_bitmap_alloc();
  if (hwloc_get_cpubind(t.topo, set, HWLOC_CPUBIND_THREAD) == 0) {
    s.set = set;
  } else {
    hwloc_bitmap_free(set);
  }
}

void restore_binding(SavedBinding& s) {
  Topology& t = topology();
  if (!t.topo || !s.set) return;
  t_bound_slot = -1;  // whatever it was before, it is no longer bound by the rule
  std::lock_guard<std::mutex> lock(hwloc_mutex());
  hwloc_set_cpubind(t.topo, static_cast<hwloc_bitmap_t>(s.set), HWLOC_CPUBIND_THREAD);
}

SavedBinding::~SavedBinding() {
  if (set) hwloc_bitmap_free(static_cast<hwloc_bitmap_t>(set));
}

double wait_tick_ns() {
#if defined(__x86_64__) || defined(__i386__)
  static const double ns = [] {
    // Both clocks read back to back at the ends of a 2 ms interval: the error is about
    // 50 ns in 2 ms.
    const std::int64_t n0 = now_ns(), c0 = wait_ticks();
    std::int64_t n1 = n0;
    while (n1 - n0 < 2'000'000) n1 = now_ns();
    const std::int64_t c1 = wait_ticks();
    return c1 > c0 ? static_cast<double>(n1 - n0) / static_cast<double>(c1 - c0) : 1.0;
  }();
  return ns;
#else
  return 1.0;
#endif
}

unsigned hardware_pus() {
  Topology& t = topology();
  if (!t.topo || t.order.empty()) return std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(t.order.size());
}

}  // namespace detail

int pinned_pu(std::uint32_t p) {
  detail::Topology& t = detail::topology();
  if (!t.topo || t.order.empty()) return -1;
  return static_cast<int>(t.order[p % t.order.size()]->os_index);
}

}  // namespace tgraph::replay
