// SPDX-License-Identifier: MIT
// Which OpenMP runtime the process's OpenMP entry points resolve to. tgraph is built with
// GCC against libgomp; LLVM's libomp implements the same GOMP_* entry points, so a process
// started with libomp preloaded (LD_PRELOAD) runs every `omp parallel`, `omp task` and
// `taskwait depend` of the barrier and omp-tasks executors on libomp, and libgomp, still
// mapped, is never called: one runtime per process.
#include <dlfcn.h>

#include <cstring>
#include <string_view>

#include "tgraph/replay/executor.hpp"

namespace tgraph::replay {

std::string_view openmp_runtime() {
  static const std::string_view name = [] {
    Dl_info info{};
    void* f = dlsym(RTLD_DEFAULT, "GOMP_parallel");
    const bool gnu = f == nullptr || dladdr(f, &info) == 0 || info.dli_fname == nullptr ||
                     std::strstr(info.dli_fname, "libgomp") != nullptr;
    return std::string_view(gnu ? "gnu" : "llvm");
  }();
  return name;
}

std::string_view llvm_openmp_library() {
#if defined(TGRAPH_LIBOMP_PATH)
  return TGRAPH_LIBOMP_PATH;
#else
  return {};
#endif
}

}  // namespace tgraph::replay
