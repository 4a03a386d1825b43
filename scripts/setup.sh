#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Shared set-up of scripts/demo and scripts/test: Debian packages, configure, build.
# Sourced, not run. Idempotent: quick when nothing changed.
set -euo pipefail

TGRAPH_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TGRAPH_PACKAGES=(cmake g++ ninja-build pkg-config python3
  libeigen3-dev libmetis-dev metis libscotch-dev scotch libgraphviz-dev graphviz
  libgtest-dev libgmock-dev libbenchmark-dev libtbb-dev libhwloc-dev libcli11-dev nlohmann-json3-dev
  libstarpu-dev zlib1g-dev clang libclang-rt-14-dev libomp-14-dev libcairo2-dev
  python3-dev python3-pybind11 pybind11-dev python3-pytest libsimgrid-dev
  liblapacke-dev liblapack-dev libblas-dev libopenmpi-dev openmpi-bin libptscotch-dev
  libode-dev)
# What `tgraph demo` needs (scripts/demo, the demo-release preset): the compiler and build
# tools, the libraries of the modules the `tgraph` binary links (Eigen for the engine, METIS
# and Scotch for the strategies, Graphviz and cairo for the report, TBB, hwloc), and StarPU,
# whose policy is one of the rows the demo compares. Not: SimGrid, ODE, OpenMPI, PT-Scotch,
# clang, GoogleTest, Google Benchmark, pybind11, LAPACK (tests, benchmarks, the Python module,
# the examples and the verbs the demo does not run; the preset leaves them out).
TGRAPH_DEMO_PACKAGES=(cmake g++ ninja-build pkg-config
  libeigen3-dev libmetis-dev libscotch-dev libgraphviz-dev libcairo2-dev
  libtbb-dev libhwloc-dev libcli11-dev nlohmann-json3-dev libstarpu-dev zlib1g-dev)

# tgraph_install_packages [PACKAGE...]: installs those missing of PACKAGE... (default:
# TGRAPH_PACKAGES, everything the tests use), and npm.
tgraph_install_packages() {
  local missing=() wanted=("$@")
  [ ${#wanted[@]} -gt 0 ] || wanted=("${TGRAPH_PACKAGES[@]}")
  for p in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  # npm (with node) fetches the report's charting libraries at build time (viz/web); any npm
  # will do, so a node from elsewhere (nodesource, nvm) is kept rather than Debian's.
  command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ "$(id -u)" -eq 0 ]; then
    echo "tgraph: installing ${missing[*]}" >&2
    DEBIAN_FRONTEND=noninteractive apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    echo "tgraph: missing Debian packages; run as root:" >&2
    echo "  apt-get install -y ${missing[*]}" >&2
    exit 2
  fi
}

# tgraph_build PRESET [-DNAME=VALUE...] [TARGET...]: configure once, then build incrementally.
# A folder not configured yet gets the preset's generator (Ninja), or TGRAPH_GENERATOR when
# set; one already configured keeps its own, and is configured again only when a -D value
# given differs from its cache (e.g. -DTGRAPH_REQUIRE_ALL=ON on a folder built without it).
tgraph_build() {
  local preset="$1"; shift
  local defs=() targets=() d
  for d in "$@"; do
    case "$d" in
      -D*) defs+=("$d") ;;
      *) targets+=("$d") ;;
    esac
  done
  cd "$TGRAPH_ROOT"
  if [ ! -f "build/$preset/CMakeCache.txt" ]; then
    if [ -n "${TGRAPH_GENERATOR:-}" ]; then
      cmake --preset "$preset" -G "$TGRAPH_GENERATOR" "${defs[@]}" >/dev/null
    else
      cmake --preset "$preset" "${defs[@]}" >/dev/null
    fi
  else
    for d in "${defs[@]}"; do
      local name="${d#-D}" value="${d#*=}"
      name="${name%%=*}"
      name="${name%%:*}"
      if ! grep -qx "$name:[A-Z]*=$value" "build/$preset/CMakeCache.txt"; then
        cmake -S . -B "build/$preset" "${defs[@]}" >/dev/null
        break
      fi
    done
  fi
  local jobs
  jobs="$(nproc 2>/dev/null || echo 2)"
  if [ ${#targets[@]} -gt 0 ]; then
    cmake --build "build/$preset" -j "$jobs" --target "${targets[@]}"
  else
    cmake --build "build/$preset" -j "$jobs"
  fi
}

# Optional: Debian's chromium for the browser test of the HTML report (tests/viz). Installed
# when running as root; otherwise, or when apt fails, a notice says the test will be skipped,
# unless TGRAPH_REQUIRE_ALL=1 (CI sets it; the configure then fails too, see scripts/test) or
# TGRAPH_REQUIRE_BROWSER=1 (the browser alone), which make a missing browser an error.
tgraph_install_browser() {
  command -v chromium >/dev/null 2>&1 && return 0
  if [ "$(id -u)" -eq 0 ] &&
    { DEBIAN_FRONTEND=noninteractive apt-get update -qq &&
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium; } >/dev/null 2>&1; then
    echo "tgraph: installed chromium (browser test of the HTML report)" >&2
    return 0
  fi
  if [ "${TGRAPH_REQUIRE_ALL:-0}" = "1" ] || [ "${TGRAPH_REQUIRE_BROWSER:-0}" = "1" ]; then
    echo "tgraph: error: chromium is not installed and could not be installed (run as root:" \
      "apt-get install chromium); TGRAPH_REQUIRE_ALL=1 (or TGRAPH_REQUIRE_BROWSER=1) asks for" \
      "the browser test" >&2
    return 1
  fi
  echo "tgraph: NOTICE: chromium is not installed and could not be installed (run as root:" \
    "apt-get install chromium); the browser test of the HTML report will be skipped" >&2
}
