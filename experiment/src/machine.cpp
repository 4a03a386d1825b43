// SPDX-License-Identifier: MIT
#include "tgraph/experiment/machine.hpp"

#include <hwloc.h>
#include <sys/utsname.h>

#include <algorithm>
#include <fstream>
#include <thread>

namespace tgraph::experiment {
namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon == std::string::npos) break;
      std::string v = line.substr(colon + 1);
      v.erase(0, v.find_first_not_of(" \t"));
      return v;
    }
  return {};
}

std::string bytes_text(std::uint64_t b) {
  if (b >= (1u << 20) && b % (1u << 20) == 0) return std::to_string(b >> 20) + " MiB";
  return std::to_string(b >> 10) + " KiB";
}

std::uint32_t count(hwloc_topology_t t, hwloc_obj_type_t type) {
  const int n = hwloc_get_nbobjs_by_type(t, type);
  return n > 0 ? static_cast<std::uint32_t>(n) : 0;
}

std::uint64_t cache_bytes(hwloc_topology_t t, hwloc_obj_type_t type) {
  hwloc_obj_t o = hwloc_get_obj_by_type(t, type, 0);
  return o != nullptr && o->attr != nullptr ? o->attr->cache.size : 0;
}

}  // namespace

std::string MachineInfo::summary() const {
  auto plural = [](std::uint32_t n, const char* word) {
    return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
  };
  std::string s = model.empty() ? std::string("unknown CPU") : model;
  s += ", " + plural(cores, "core") + " (" + plural(pus, "hardware thread") + "), " +
       plural(packages, "socket") + ", " + plural(numa_nodes, "NUMA node");
  if (l2_bytes) s += ", L2 " + bytes_text(l2_bytes);
  if (l3_bytes) s += ", L3 " + bytes_text(l3_bytes);
  return s;
}

MachineInfo probe_machine() {
  MachineInfo m;
  m.model = cpu_model();
  m.pus = m.cores = std::max(1u, std::thread::hardware_concurrency());
  utsname u{};
  if (uname(&u) == 0) m.os = std::string(u.sysname) + " " + u.release;
  hwloc_topology_t t = nullptr;
  if (hwloc_topology_init(&t) != 0) return m;
  if (hwloc_topology_load(t) != 0) {
    hwloc_topology_destroy(t);
    return m;
  }
  if (const std::uint32_t c = count(t, HWLOC_OBJ_CORE)) m.cores = c;
  if (const std::uint32_t p = count(t, HWLOC_OBJ_PU)) m.pus = p;
  m.packages = std::max(1u, count(t, HWLOC_OBJ_PACKAGE));
  m.numa_nodes = std::max(1u, count(t, HWLOC_OBJ_NUMANODE));
  m.l2_bytes = cache_bytes(t, HWLOC_OBJ_L2CACHE);
  m.l3_bytes = cache_bytes(t, HWLOC_OBJ_L3CACHE);
  if (m.model.empty())
    if (hwloc_obj_t pkg = hwloc_get_obj_by_type(t, HWLOC_OBJ_PACKAGE, 0))
      if (const char* v = hwloc_obj_get_info_by_name(pkg, "CPUModel")) m.model = v;
  hwloc_topology_destroy(t);
  return m;
}

}  // namespace tgraph::experiment
