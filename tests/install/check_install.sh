#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the build into a temporary prefix, then, as a user of the package would:
# builds one consumer per component (tests/install/consumers: find_package(tgraph COMPONENTS
# <one>), calls into it and checks the results; capture's without oneTBB), checks that a
# component whose dependency is missing is refused by name; builds examples/tiled-lu with the
# capture component only (-DTILED_LU_LIVE=OFF, oneTBB disabled) and checks its trace's task
# and edge counts against the analytic ones, then with COMPONENTS capture measure and runs it
# live on 2 threads (check "identical", residual small); builds examples/instrument-your-engine
# (COMPONENTS capture measure), runs it, checks its trace with the installed
# `tgraph info --json` and runs it live on 2 threads (check "identical"), and builds it again
# with pkg-config (capture only: --live refused); builds examples/ode-attach (COMPONENTS ode,
# when tgraph::ode is installed) and runs it on 2 threads (check not "differs"); then imports
# the installed Python module
# and runs pytest on it. No speed-up is asserted (a noisy machine): docs/instrumenting.md
# gives the measured ones with their commands.
#   check_install.sh BUILD_DIR SOURCE_DIR [PYTHON]   (PYTHON: the interpreter with pytest)
set -euo pipefail
build="$(cd "$1" && pwd)"
src="$(cd "$2" && pwd)"
python="${3:-python3}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"

step() { echo "== $*"; }
step "install into $prefix"
cmake --install "$build" --prefix "$prefix" > "$tmp/install.log"
for f in bin/tgraph include/tgraph/capture/recorder.hpp include/tgraph/graph/trace_io.hpp \
         include/tgraph/version.hpp \
         lib/cmake/tgraph/tgraphConfig.cmake lib/cmake/tgraph/tgraphConfigVersion.cmake \
         lib/pkgconfig/tgraph.pc; do
  [ -e "$prefix/$f" ] || { echo "missing after install: $f" >&2; exit 1; }
done

# configure_and_build SRC BUILD [cmake args...]: the default generator, like a new user.
configure_and_build() {
  local srcdir="$1" bdir="$2"
  shift 2
  cmake -S "$srcdir" -B "$bdir" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" "$@" \
    > "$bdir.configure.log" 2>&1 || { cat "$bdir.configure.log"; return 1; }
  cmake --build "$bdir" -j 2 > "$bdir.build.log" 2>&1 || { cat "$bdir.build.log"; return 1; }
}

consumers="$src/tests/install/consumers"
for component in graph capture model partition replay viz measure; do
  if [ ! -f "$prefix/lib/cmake/tgraph/tgraph-$component-targets.cmake" ]; then
    echo "== component $component not built (TGRAPH_SKIP_MODULES): no consumer"
    continue
  fi
  args=(-DCOMPONENT="$component")
  note=""
  if [ "$component" = capture ]; then
    # The capture API needs none of the other modules' libraries.
    args+=(-DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON -DCMAKE_DISABLE_FIND_PACKAGE_OpenMP=ON
           -DCMAKE_DISABLE_FIND_PACKAGE_Eigen3=ON)
    note=" (oneTBB, OpenMP and Eigen disabled)"
  fi
  step "consumer of tgraph::$component: configure$note, build, run"
  configure_and_build "$consumers" "$tmp/consumer-$component" "${args[@]}"
  "$tmp/consumer-$component/consumer"
done

if [ -f "$prefix/lib/cmake/tgraph/tgraph-replay-targets.cmake" ]; then
  step "find_package(tgraph COMPONENTS replay) without oneTBB is refused, naming it"
  if cmake -S "$consumers" -B "$tmp/consumer-no-tbb" -DCMAKE_PREFIX_PATH="$prefix" \
       -DCOMPONENT=replay -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON > "$tmp/consumer-no-tbb.log" 2>&1; then
    echo "configured tgraph::replay without oneTBB" >&2; exit 1
  fi
  # (CMake wraps the message: joined into one line first)
  tr -s ' \n' '  ' < "$tmp/consumer-no-tbb.log" | grep -q "replay needs TBB::tbb (Debian libtbb-dev)" ||
    { cat "$tmp/consumer-no-tbb.log"; echo "the refusal does not name TBB::tbb" >&2; exit 1; }
fi

lu="$src/examples/tiled-lu"
step "configure and build $lu against the package (capture only, LAPACKE/CBLAS)"
configure_and_build "$lu" "$tmp/lu" -DTILED_LU_LIVE=OFF -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON
nt=6
"$tmp/lu/tiled_lu" "$nt" 32 "$tmp/lu.tgt" 3
rc=0
"$tmp/lu/tiled_lu" "$nt" 32 "$tmp/lu-refused.tgt" --live 2 2> "$tmp/lu-refused.err" || rc=$?
[ "$rc" = 2 ] && grep -q "built without tgraph::measure" "$tmp/lu-refused.err" ||
  { cat "$tmp/lu-refused.err"; echo "--live without the measure component: exit $rc" >&2; exit 1; }
"$prefix/bin/tgraph" info "$tmp/lu.tgt" --json > "$tmp/lu.json"
"$python" - "$tmp/lu.json" "$nt" <<'PY'
import json, sys
j, nt = json.load(open(sys.argv[1])), int(sys.argv[2])
# One FILL per tile, then per k (m = NT-k-1 tiles below and right of the diagonal): 1 GETRF,
# 2m TRSM, m^2 GEMM.
tasks = nt * nt + sum(1 + 2 * m + m * m for m in range(nt))
# Tile (i,j), p = min(i,j), is written by its FILL (W), then updated in place (RW) by the
# GEMMs of steps 0..p-1 and by GETRF or TRSM at step p, with no reader between: a RAW chain
# of p + 1 edges (RW after W or RW is RAW, never WAW). Then it is only read: (p,p) by the 2m
# TRSMs of step p, each of the 2m panel tiles of step p by m GEMMs: RAW edges from the final
# writer, no WAR (no later write). FILL's own matrix number is touched by it alone.
chains = sum(min(i, j) + 1 for i in range(nt) for j in range(nt))
reads = sum(2 * m + 2 * m * m for m in range(nt))
edges = chains + reads
got = [(s["tasks"], s["edges"]) for s in j["per_step"]]
if j["steps"] != 3 or any(g != (tasks, edges) for g in got):
    sys.exit(f"tiled LU {nt}x{nt}: expected {tasks} tasks and {edges} edges per step, got {got}")
print(f"ok: tiled LU {nt}x{nt}: {tasks} tasks and {edges} edges per step, as derived")
PY

# check_live JSON METHOD: the one JSON object of a live run, checked (no speed-up asserted).
check_live() {
  "$python" - "$1" "$2" <<'PY'
import json, sys
text = open(sys.argv[1]).read()
j = json.loads(text)  # one object, nothing else on stdout
bad = [k for k, ok in [("check", j.get("check") == "identical"), ("threads", j.get("threads") == 2),
                       ("method", j.get("method") == sys.argv[2]),
                       ("speedup", j.get("speedup", 0) > 0),
                       ("residual", "residual" not in j or j["residual"] < 1e-12)] if not ok]
if bad:
    sys.exit("live run: wrong " + ", ".join(bad) + ":\n" + text[:2000])
print(f"ok: live on 2 threads ({j['method']}): check {j['check']}, speed-up {j['speedup']:.2f}"
      + (f", residual {j['residual']:.2e}" if "residual" in j else ""))
PY
}

step "configure and build $lu with COMPONENTS capture measure; run it live on 2 threads"
configure_and_build "$lu" "$tmp/lu-live"
"$tmp/lu-live/tiled_lu" 8 64 "$tmp/lu-live.tgt" 2 --live 2 --repeat 1 --json > "$tmp/lu-live.json"
check_live "$tmp/lu-live.json" list

example="$src/examples/instrument-your-engine"
step "configure and build $example against the package (COMPONENTS capture measure)"
configure_and_build "$example" "$tmp/example"

step "run it: 20 steps -> springs.tgt (it reads the trace back and checks it)"
"$tmp/example/springs" 20 "$tmp/springs.tgt"

step "tgraph info --json springs.tgt (installed binary)"
"$prefix/bin/tgraph" info "$tmp/springs.tgt" --json > "$tmp/info.json"
"$python" - "$tmp/info.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
# 4 x 2 sub-sheets of 48 x 48 particles, 10 seams between neighbours (3 x 2 across, 4 down):
# per sheet resetForce, integrate, clearDelta, applyDelta; per spring set (a sheet's own
# springs or a seam) addForce and projectLength; checkResidual and the loop's break.
sheets, sets = 8, 8 + 10
tasks = 4 * sheets + 2 * sets + 2
checks = [
    ("scene", j["scene"] == "springs 4x2 sheets of 48x48"),
    ("steps", j["steps"] == 20),
    ("tasks per step", j["tasks_per_step"]["min"] == tasks == j["tasks_per_step"]["max"]),
    ("one loop per step", j["loops"] == 20 and all(s["loops"] == 1 for s in j["per_step"])),
    # the projection loop runs 1..12 times and more than once once the sheet stretches
    ("loop iterations", all(1 <= s["loop_iterations"][0] <= 12 for s in j["per_step"])
     and max(s["loop_iterations"][0] for s in j["per_step"]) > 1),
    ("one structure", j["distinct_structures"] == 1),
    # every step has the same edges; at least one per spring set into each integrate it feeds
    ("edges", len({s["edges"] for s in j["per_step"]}) == 1
     and j["per_step"][0]["edges"] >= sheets + 2 * (sets - sheets)),
    ("parallelism", j["parallelism"] > 1.0),
]
bad = [name for name, ok in checks if not ok]
if bad:
    sys.exit("tgraph info --json: wrong " + ", ".join(bad) + ":\n" + json.dumps(j)[:2000])
print(f"ok: {j['steps']} steps, {tasks} tasks and {j['per_step'][0]['edges']} edges per step, "
      f"{j['loop_iterations']} loop iterations, parallelism {j['parallelism']:.2f}")
PY

step "run it live: 10 steps on 2 threads through tgraph's executor, checked"
"$tmp/example/springs" 10 "$tmp/springs-live.tgt" --live 2 --repeat 1 --json > "$tmp/springs-live.json"
check_live "$tmp/springs-live.json" owner

step "build the same engine with pkg-config (tgraph.pc)"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
# shellcheck disable=SC2046
c++ -O2 -DTGRAPH_PACKAGE_VERSION="\"$(pkg-config --modversion tgraph)\"" \
  "$example/springs.cpp" -o "$tmp/springs-pc" $(pkg-config --cflags --libs tgraph)
"$tmp/springs-pc" 3 "$tmp/springs-pc.tgt"
rc=0
"$tmp/springs-pc" 3 "$tmp/springs-pc.tgt" --live 2 2> "$tmp/springs-pc.err" || rc=$?
[ "$rc" = 2 ] || { cat "$tmp/springs-pc.err"; echo "--live with the capture API only: exit $rc" >&2; exit 1; }
if [ -e "$prefix/lib/cmake/tgraph/tgraph-ode-targets.cmake" ]; then
  example="$src/examples/ode-attach"
  step "configure and build $example against the package (COMPONENTS ode); run it on 2 threads"
  configure_and_build "$example" "$tmp/ode-attach"
  "$tmp/ode-attach/ode_attach" 40 --threads 2 --json > "$tmp/ode-attach.json"
  "$python" - "$tmp/ode-attach.json" <<'PY'
import json, sys
text = open(sys.argv[1]).read()
j = json.loads(text)  # one object, nothing else on stdout
bad = [k for k, ok in [("check", j.get("check") in ("identical", "within-rounding", "within-tolerance")),
                       ("threads", j.get("threads") == 2), ("method", j.get("method") == "islands-serial"),
                       ("speedup", j.get("speedup", 0) > 0)] if not ok]
if bad:
    sys.exit("ode_attach: wrong " + ", ".join(bad) + ":\n" + text[:2000])
print(f"ok: ode_attach on 2 threads: check {j['check']}, speed-up {j['speedup']:.2f}")
PY
fi
if [ -n "$(find "$prefix" -path '*/tgraph/_tgraph*.so' -print -quit)" ]; then
  init="$(find "$prefix" -path '*/tgraph/__init__.py' -print -quit)"
  pydir="$(dirname "$(dirname "$init")")"
  step "Python module from the prefix (PYTHONPATH=$pydir)"
  cp "$tmp/springs.tgt" "$tmp/b.tgt"
  out="$(cd "$tmp" && PYTHONPATH="$pydir" python3 -c \
    "import tgraph; t = tgraph.read_trace('b.tgt'); print(t.steps, t.metrics(0).parallelism)")"
  echo "$out"
  [ "${out%% *}" = "20" ] || { echo "expected 20 steps from the Python module" >&2; exit 1; }
  step "pytest tests/python against the installed module and binary"
  (cd "$tmp" && PYTHONPATH="$pydir" TGRAPH_BIN="$prefix/bin/tgraph" \
    TGRAPH_TEST_DATA="$src/tests/data" "$python" -m pytest -q -p no:cacheprovider "$src/tests/python")
fi
echo "install check passed"
