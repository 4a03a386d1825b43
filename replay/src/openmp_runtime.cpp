// SPDX-License-Identifier: MIT
// Which OpenMP runtime the process's OpenMP entry points resolve to. tgraph is built with
// GCC against libgomp; LLVM's libomp implements the same GOMP_* entry points, so a process
// started with libomp preloaded (LD_PRELOAD) runs every `omp parallel`, `omp task` and
// `taskwait depend` of the barrier and omp-tasks executors on libomp, and libgomp, still
// mapped, is never called: one runtime per process.
#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/error.hpp"
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

void use_openmp_runtime(std::string_view want) {
  if (want != "gnu" && want != "llvm")
    throw OptionError("openmp_runtime", "expected gnu or llvm, got '" + std::string(want) + "'");
  if (want == openmp_runtime()) return;
  if (want == "gnu")
    throw OptionError("openmp_runtime",
                      "gnu, but this process was started with LLVM's OpenMP runtime preloaded "
                      "(LD_PRELOAD); start it without");
  const std::string lib(llvm_openmp_library());
  if (lib.empty() || access(lib.c_str(), R_OK) != 0)
    throw OptionError("openmp_runtime",
                      "llvm, but LLVM's OpenMP runtime is not installed (Debian libomp-dev)" +
                          (lib.empty() ? std::string() : ": no " + lib));
  // Failures of the restart are failures of the work (exit 1), not of the options.
  if (std::getenv("TGRAPH_OPENMP_RESTARTED") != nullptr)
    throw std::runtime_error("OpenMP: preloading " + lib + " did not replace libgomp");
  // The same command line again, from /proc (NUL-separated arguments).
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string line((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> args;
  for (std::size_t b = 0; b < line.size();) {
    const std::size_t e = line.find('\0', b);
    args.push_back(line.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const char* old = std::getenv("LD_PRELOAD");
  const std::string preload = old != nullptr && *old != '\0' ? lib + ":" + old : lib;
  setenv("LD_PRELOAD", preload.c_str(), 1);
  setenv("TGRAPH_OPENMP_RESTARTED", "1", 1);
  std::cout.flush();
  execv("/proc/self/exe", argv.data());
  throw std::runtime_error("OpenMP: could not restart the process with " + lib);
}

}  // namespace tgraph::replay
