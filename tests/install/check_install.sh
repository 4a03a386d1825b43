#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the build into a temporary prefix, then, as a user of the package would:
# builds examples/instrument-your-engine with find_package(tgraph) and again with
# pkg-config, runs it to write a trace and checks the trace with the installed
# `tgraph info --json`; then imports the installed Python module and runs pytest on it.
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
         lib/cmake/tgraph/tgraphConfig.cmake lib/cmake/tgraph/tgraphConfigVersion.cmake \
         lib/pkgconfig/tgraph.pc; do
  [ -e "$prefix/$f" ] || { echo "missing after install: $f" >&2; exit 1; }
done

example="$src/examples/instrument-your-engine"
step "configure and build $example against the package"
cmake -S "$example" -B "$tmp/example" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" > "$tmp/configure.log" || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/example" > "$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }

step "run it: 20 steps -> springs.tgt (it reads the trace back and checks it)"
"$tmp/example/springs" 20 "$tmp/springs.tgt"

step "tgraph info --json springs.tgt (installed binary)"
"$prefix/bin/tgraph" info "$tmp/springs.tgt" --json > "$tmp/info.json"
"$python" - "$tmp/info.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
# 16 particles, 24 springs: resetForce, integrate, clearDelta, applyDelta per particle,
# addForce and projectLength per spring, checkResidual and the loop's break.
tasks = 4 * 16 + 2 * 24 + 2
checks = [
    ("scene", j["scene"] == "springs 4x4"),
    ("steps", j["steps"] == 20),
    ("tasks per step", j["tasks_per_step"]["min"] == tasks == j["tasks_per_step"]["max"]),
    ("one loop per step", j["loops"] == 20 and all(s["loops"] == 1 for s in j["per_step"])),
    # the projection loop runs 1..20 times and more than once once the sheet stretches
    ("loop iterations", all(1 <= s["loop_iterations"][0] <= 20 for s in j["per_step"])
     and max(s["loop_iterations"][0] for s in j["per_step"]) > 1),
    ("one structure", j["distinct_structures"] == 1),
    # every step has the same edges; at least 2 per spring (addForce -> 2 integrates)
    ("edges", len({s["edges"] for s in j["per_step"]}) == 1 and j["per_step"][0]["edges"] >= 48),
    ("parallelism", j["parallelism"] > 1.0),
]
bad = [name for name, ok in checks if not ok]
if bad:
    sys.exit("tgraph info --json: wrong " + ", ".join(bad) + ":\n" + json.dumps(j)[:2000])
print(f"ok: {j['steps']} steps, {tasks} tasks and {j['per_step'][0]['edges']} edges per step, "
      f"{j['loop_iterations']} loop iterations, parallelism {j['parallelism']:.2f}")
PY

step "build the same engine with pkg-config (tgraph.pc)"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
# shellcheck disable=SC2046
c++ -O2 -DTGRAPH_PACKAGE_VERSION="\"$(pkg-config --modversion tgraph)\"" \
  "$example/springs.cpp" -o "$tmp/springs-pc" $(pkg-config --cflags --libs tgraph)
"$tmp/springs-pc" 3 "$tmp/springs-pc.tgt"
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
