#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The viz verbs end to end: the commands of issue 9's "done means", bad input (exit 2, one
# line, no file written), and `dot -Tsvg` on every .dot written.
# Usage: viz_cli.sh TGRAPH DOT
set -euo pipefail
T="$1"
DOT="$2"
d="$(mktemp -d)"
trap 'rm -rf "$d"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# expect_refusal OUTPUT CMD...: exit 2, one line on stderr, OUTPUT not written.
expect_refusal() {
  local out="$1"; shift
  set +e
  "$@" >"$d/out" 2>"$d/err"
  local rc=$?
  set -e
  [ "$rc" -eq 2 ] || fail "$* exited $rc, expected 2: $(cat "$d/err")"
  [ "$(wc -l <"$d/err")" -eq 1 ] || fail "$*: expected a one-line error, got: $(cat "$d/err")"
  [ ! -e "$out" ] || fail "$*: wrote $out"
}

"$T" capture --scene fig2 --steps 3 -o "$d/fig2.tgt" >/dev/null
# owner: one processor per object, both used whatever the measured costs (METIS may leave a
# part empty on fig2's nine tiny tasks).
"$T" partition "$d/fig2.tgt" --method owner -k 2 -o "$d/f2.tga" >/dev/null
"$T" viz "$d/fig2.tgt" --step 1 --assign "$d/f2.tga" -o "$d/f.svg"
# Each colour at least twice: its legend sample and at least one node or edge.
[ "$(grep -ci 'fill="#e69f00"' "$d/f.svg")" -ge 2 ] || fail "f.svg: no node filled with p0's colour"
[ "$(grep -ci 'fill="#56b4e9"' "$d/f.svg")" -ge 2 ] || fail "f.svg: no node filled with p1's colour"
[ "$(grep -ci 'stroke="#d55e00"' "$d/f.svg")" -ge 2 ] || fail "f.svg: no red crossing edge"
for c in none object kind processor loop; do
  "$T" viz "$d/fig2.tgt" --step 1 --assign "$d/f2.tga" --collapse "$c" --critical-path -o "$d/f_$c.dot"
done
"$T" viz "$d/fig2.tgt" --step 1 -o "$d/plain.dot"
"$T" viz "$d/fig2.tgt" --step 1 --assign "$d/f2.tga" -o "$d/f.png"
[ "$(head -c 4 "$d/f.png" | tail -c 3)" = "PNG" ] || fail "f.png is not a PNG"

"$T" capture --scene bars64 --steps 2 -o "$d/b.tgt" >/dev/null
"$T" viz "$d/b.tgt" --step 1 --collapse object -o "$d/b.svg"
grep -q '<svg' "$d/b.svg" || fail "b.svg is not an SVG"
"$T" viz "$d/b.tgt" --step 1 --collapse kind --critical-path -o "$d/b_kind.dot"
# A collapsed view says how many dependencies it hides as self-loops: on stderr, out of the
# step's dependencies as `info` counts them, and in the picture's title.
"$T" viz "$d/b.tgt" --step 1 --collapse object -o "$d/b_obj.svg" 2>"$d/err"
deps="$("$T" info "$d/b.tgt" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["per_step"][1]["edges"])')"
grep -Eq "^tgraph viz: [1-9][0-9]* of $deps dependencies join tasks of one node \(self-loops, not drawn\)\$" "$d/err" \
  || fail "viz --collapse object does not say what it hides out of $deps: $(cat "$d/err")"
sed 's/&#45;/-/g' "$d/b_obj.svg" >"$d/b_obj.txt"  # SVG writes '-' as &#45;
grep -qF "$(sed 's/^tgraph viz: //' "$d/err")" "$d/b_obj.txt" || fail "b_obj.svg's title does not say what it hides"
"$T" viz "$d/fig2.tgt" --step 1 -o "$d/plain2.dot" 2>"$d/err"
[ ! -s "$d/err" ] || fail "viz without --collapse printed: $(cat "$d/err")"
expect_refusal "$d/nb.svg" "$T" viz "$d/b.tgt" --step 1 -o "$d/nb.svg"
grep -q -- '--collapse' "$d/err" || fail "refusal does not suggest --collapse: $(cat "$d/err")"
expect_refusal "$d/x.jpeg" "$T" viz "$d/fig2.tgt" --step 1 -o "$d/x.jpeg"
expect_refusal "$d/x.svg" "$T" viz "$d/fig2.tgt" --step 9 -o "$d/x.svg"
expect_refusal "$d/x.svg" "$T" viz "$d/fig2.tgt" --collapse objects -o "$d/x.svg"
expect_refusal "$d/x.svg" "$T" viz "$d/fig2.tgt" --collapse processor -o "$d/x.svg"
expect_refusal "$d/x.svg" "$T" viz "$d/b.tgt" --assign "$d/f2.tga" -o "$d/x.svg"

for f in "$d"/*.dot; do
  "$DOT" -Tsvg "$f" -o "$f.svg" || fail "dot -Tsvg rejects $(basename "$f")"
done

"$T" replay "$d/fig2.tgt" --threads 2 --steps 2 --repeat 1 --timeline "$d/r.json" >/dev/null
"$T" timeline "$d/r.json" -o "$d/r.svg"
grep -q '<svg' "$d/r.svg" || fail "r.svg is not an SVG"
"$T" timeline "$d/r.json" --steps 1:1 -o "$d/r.png"
[ "$(head -c 4 "$d/r.png" | tail -c 3)" = "PNG" ] || fail "r.png is not a PNG"
"$T" export "$d/r.json" --format chrome -o "$d/chrome.json"
python3 -c "import json,sys; e=json.load(open(sys.argv[1]))['traceEvents']; assert any(x['ph']=='X' for x in e)" "$d/chrome.json" \
  || fail "chrome trace has no events"
echo '{"tasks": [' >"$d/bad.json"
expect_refusal "$d/x.svg" "$T" timeline "$d/bad.json" -o "$d/x.svg"
expect_refusal "$d/x.svg" "$T" timeline "$d/r.json" --steps 7:9 -o "$d/x.svg"
expect_refusal "$d/x.gif" "$T" timeline "$d/r.json" -o "$d/x.gif"

"$T" compare "$d/fig2.tgt" --methods metis,owner -k 2 --json >"$d/cmp.json"
"$T" replay "$d/fig2.tgt" --threads 2 --repeat 1 --json >"$d/rep.json"
"$T" report "$d/fig2.tgt" --replay "$d/r.json" --replay "$d/rep.json" --compare "$d/cmp.json" \
  --assign "$d/f2.tga" -o "$d/report.html" >/dev/null
for id in chart-speedup chart-methods chart-timeline; do
  grep -q "id=\"$id\"" "$d/report.html" || fail "report.html has no $id"
done
! grep -q '<script src' "$d/report.html" || fail "report.html loads a script from elsewhere"
# The timeline replayed steps 0 and 1: step 1's graph draws the executed critical path, step
# 2's (not in the timeline) the graph's own longest path.
grep -q "executed critical path (thick, double border): .* over [1-9][0-9]* task instances" "$d/report.html" ||
  fail "report.html's step graph does not draw the timeline's executed critical path"
"$T" report "$d/fig2.tgt" --replay "$d/r.json" --step 2 -o "$d/report2.html" >/dev/null
grep -q "critical path (thick, double border)" "$d/report2.html" || fail "report2.html draws no critical path"
! grep -q "executed critical path (thick" "$d/report2.html" ||
  fail "report2.html draws an executed path for a step the timeline does not hold"
expect_refusal "$d/y.html" "$T" report "$d/fig2.tgt" --compare "$d/r.json" -o "$d/y.html"
echo "viz command line: all checks passed"
