// SPDX-License-Identifier: MIT
// Shared main() of the benchmark binaries: a --tgraph_size flag picks how big and how long.
#pragma once

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace tgraph::bench {

/// How much a benchmark binary measures (`--tgraph_size=smoke|quick|full`, default full).
enum class Size : unsigned char {
  kSmoke = 0,  ///< smallest arguments, one iteration each: does every benchmark still run?
  kQuick = 1,  ///< fewer arguments and shorter runs (`scripts/bench --quick`)
  kFull = 2,   ///< what docs/benchmarks.md quotes
};

/// "smoke", "quick" or "full".
inline std::string_view to_string(Size s) {
  switch (s) {
    case Size::kSmoke:
      return "smoke";
    case Size::kQuick:
      return "quick";
    case Size::kFull:
      return "full";
  }
  return "?";
}

/// Removes `--tgraph_size=X` from argv and returns it; one line on stderr and exit 2 for an
/// unknown X.
inline Size parse_size(int& argc, char** argv) {
  constexpr std::string_view kFlag = "--tgraph_size=";
  Size size = Size::kFull;
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (!arg.starts_with(kFlag)) {
      argv[out++] = argv[i];
      continue;
    }
    const std::string_view v = arg.substr(kFlag.size());
    if (v == "smoke") {
      size = Size::kSmoke;
    } else if (v == "quick") {
      size = Size::kQuick;
    } else if (v == "full") {
      size = Size::kFull;
    } else {
      std::fprintf(stderr, "%s: --tgraph_size: expected smoke, quick or full, got '%.*s'\n",
                   argv[0], static_cast<int>(v.size()), v.data());
      std::exit(2);
    }
  }
  argc = out;
  argv[argc] = nullptr;
  return size;
}

/// Applies the size to one benchmark: one iteration in smoke runs, else at least
/// `full_min_time` seconds per repetition (a quarter of it in quick runs).
inline benchmark::internal::Benchmark* timed(benchmark::internal::Benchmark* b, Size size,
                                             double full_min_time) {
  switch (size) {
    case Size::kSmoke:
      return b->Iterations(1);
    case Size::kQuick:
      return b->MinTime(full_min_time / 4);
    case Size::kFull:
      return b->MinTime(full_min_time);
  }
  return b;
}

/// Picks a value by size.
template <class T>
T by_size(Size size, T smoke, T quick, T full) {
  switch (size) {
    case Size::kSmoke:
      return smoke;
    case Size::kQuick:
      return quick;
    case Size::kFull:
      return full;
  }
  return full;
}

/// main() of a benchmark binary whose benchmarks `register_all(size)` registers.
inline int run_main(int argc, char** argv, void (*register_all)(Size)) {
  const Size size = parse_size(argc, argv);
  register_all(size);
  benchmark::AddCustomContext("tgraph_size", std::string(to_string(size)));
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace tgraph::bench
