#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Corrupts a valid trace COUNT times (byte flips, truncations, insertions, deletions; fixed
# seed) and runs `tgraph info` on each copy. Every copy must be rejected with exit 2 and a
# one-line message on stderr, or (rarely) still be a valid trace with exit 0; a crash
# (exit >= 128), a hang (timeout, exit 124) or any other status fails.
#
#   tests/apps/corrupt_traces.sh build/release/apps/tgraph tests/data/traces/small.tgt [1000]
set -euo pipefail

if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 TGRAPH_BINARY VALID_TRACE [COUNT=1000]" >&2
  exit 2
fi
tgraph=$1
trace=$2
count=${3:-1000}
seed=${CORRUPT_SEED:-20261122}

[[ -x "$tgraph" ]] || { echo "$0: $tgraph: not an executable" >&2; exit 2; }
[[ -f "$trace" ]] || { echo "$0: $trace: no such file" >&2; exit 2; }
if ! "$tgraph" info "$trace" >/dev/null 2>&1; then
  echo "$0: $trace: tgraph info does not accept the original trace" >&2
  exit 2
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/corrupt_traces.XXXXXX")
trap 'rm -rf "$work"' EXIT

# The corrupted copies: corrupt_NNNN.tgt, each with one to three random edits.
python3 - "$trace" "$work" "$count" "$seed" <<'PY'
import random, sys
src, out, count, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
original = open(src, "rb").read()
rng = random.Random(seed)
for i in range(count):
    b = bytearray(original)
    for _ in range(rng.randint(1, 3)):
        op = rng.choice(["flip", "flip", "byte", "truncate", "insert", "delete"])
        if not b:
            b = bytearray(rng.randbytes(rng.randint(0, 16)))
            continue
        p = rng.randrange(len(b))
        if op == "flip":
            b[p] ^= 1 << rng.randrange(8)
        elif op == "byte":
            b[p] = rng.randrange(256)
        elif op == "truncate":
            del b[p:]
        elif op == "insert":
            b[p:p] = rng.randbytes(rng.randint(1, 8))
        else:
            del b[p:p + rng.randint(1, 8)]
    if bytes(b) == original:  # an edit may undo another: force a difference
        b.append(rng.randrange(256))
    with open(f"{out}/corrupt_{i:04d}.tgt", "wb") as f:
        f.write(b)
PY

passed=0
failed=0
still_valid=0
for ((i = 0; i < count; ++i)); do
  copy=$(printf '%s/corrupt_%04d.tgt' "$work" "$i")
  set +e
  timeout 10 "$tgraph" info "$copy" >"$work/out" 2>"$work/err"
  status=$?
  set -e
  lines=$(wc -l <"$work/err")
  chars=$(wc -c <"$work/err")
  if [[ $status -eq 2 && $chars -gt 1 && $lines -eq 1 ]]; then
    passed=$((passed + 1))
  elif [[ $status -eq 0 ]]; then
    passed=$((passed + 1))
    still_valid=$((still_valid + 1))
  else
    failed=$((failed + 1))
    reason="exit $status"
    [[ $status -eq 124 ]] && reason="hang (timeout, exit 124)"
    [[ $status -ge 128 && $status -ne 124 ]] && reason="crash (exit $status)"
    [[ $status -eq 2 ]] && reason="exit 2 with $lines stderr lines"
    echo "FAIL corrupt_$(printf '%04d' "$i"): $reason: $(head -c 300 "$work/err")" >&2
    if [[ -n "${CORRUPT_KEEP:-}" ]]; then cp "$copy" "$CORRUPT_KEEP/"; fi
  fi
done

echo "$passed passed, $failed failed ($still_valid copies still read as valid traces; seed $seed)"
[[ $failed -eq 0 ]]
