#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# `tgraph experiment scaling --quick --out D --json` end to end: the `scaling` records on stdout
# and in results.json, one per (scene, method, threads) asked for, every key and nothing else,
# values in their ranges; results.csv, the charts. No timing assertions (the figures depend on
# the machine and its load).
#   check_scaling.py TGRAPH
import csv
import os
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from experiment_check import check, problems, run_quick_json  # noqa: E402

tgraph = sys.argv[1]
KEYS = {"scene", "policy", "method", "threads", "speedup", "serial_share", "inflation",
        "wait_share", "parks_per_step", "partitioned_steps", "predicted_speedup",
        "predicted_over_live", "attribution"}
CAUSES = {"serial", "imbalance", "dependency_wait", "handoff", "interruption", "inflation",
          "runtime", "starvation", "residual"}
SCENES = {"bars64": 2, "falling64": 3, "torso": 3, "cloth256-s64": 1}  # --quick's steps
BASELINES = {"worksteal", "barrier", "omp-tasks", "starpu"}

with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "scaling")
    j = run_quick_json(tgraph, "scaling", out, timeout=600)
    print(f"scaling: {len(j['scaling'])} records, {len(j['skipped'])} skipped, "
          f"{j['seconds']:.0f} s")
    check(j["threads"] == [1, 2], f"threads {j['threads']}: --quick asks for 1,2")
    check(j["failed"] == [], f"failed runs {j['failed']}")
    methods = j["methods"]
    check(methods == ["owner", "sticky", "worksteal", "barrier"], f"--quick's methods {methods}")
    refs = {r["scene"]: r for r in j["references"]}
    check(set(refs) == set(SCENES), f"references {sorted(refs)}")
    for scene, steps in SCENES.items():
        r = refs.get(scene, {})
        check(r.get("steps") == steps and r.get("sequential_wall_ns", 0) > 0, f"reference {r}")
    seen = {}
    for r in j["scaling"]:
        check(set(r) == KEYS, f"record keys {sorted(r)}")
        key = (r["scene"], r["method"], r["threads"])
        check(key not in seen, f"{key} twice")
        seen[key] = r
        steps = SCENES.get(r["scene"])
        check(steps is not None, f"unknown scene in {r}")
        check(r["threads"] in (1, 2), f"threads of {r}")
        baseline = r["method"] in BASELINES
        check(r["policy"] == (r["method"] if baseline else "partition"), f"policy of {r}")
        check(0 < r["speedup"] < 4 * r["threads"], f"speedup of {r}")
        # The main thread's serial work is a part of the live run: at most its wall time,
        # which is sequential / speedup.
        check(0 <= r["serial_share"] <= 1.0 / r["speedup"] + 1e-9, f"serial_share of {r}")
        # Busy time over the same instances' sequential time: near 1 on a quiet machine, but
        # the two passes share the cores with whatever else runs (0.19 and 1.8 were seen at
        # a load of 16 on 2 cores), so only its presence and a loose range are checked.
        check(0.05 < r["inflation"] < 20, f"inflation of {r}")
        check(0 <= r["wait_share"] < 1, f"wait_share of {r}")
        check(r["parks_per_step"] >= 0, f"parks_per_step of {r}")
        a = r.get("attribution") or {}
        causes = a.get("causes", {})
        check(set(causes) == CAUSES, f"attribution causes of {r}")
        check(sum(causes.values()) == a.get("lost_ns"), f"attribution of {r} does not add up")
        check(isinstance(r["partitioned_steps"], int) and
              0 <= r["partitioned_steps"] <= (steps or 0), f"partitioned_steps of {r}")
        if baseline:
            check(r["partitioned_steps"] == 0, f"a baseline partitioned: {r}")
            check(r["predicted_speedup"] is None and r["predicted_over_live"] is None,
                  f"a baseline with a prediction: {r}")
        else:
            check(r["partitioned_steps"] >= 1, f"the first step was not partitioned: {r}")
            # The simulator's speed-up of the same steps, beside the live one: about the thread
            # count at most (one processor's makespan with the engine's host time over K's with
            # the live run's serial work), and the ratio is the two's.
            p = r["predicted_speedup"]
            check(p is not None and 0 < p <= 1.1 * r["threads"], f"predicted_speedup of {r}")
            if p is not None:
                check(abs(r["predicted_over_live"] - p / r["speedup"]) < 1e-9 * p / r["speedup"],
                      f"predicted_over_live of {r}")
    skipped = {(s["scene"], s["method"], s["threads"]) for s in j["skipped"]}
    for scene in SCENES:
        for m in methods:
            for k in (1, 2):
                check((scene, m, k) in seen or (scene, m, k) in skipped,
                      f"no record for {scene} {m} K={k}")
    for s in j["skipped"]:
        check(s["reason"] != "", f"skipped without a reason: {s}")
    with open(os.path.join(out, "results.csv")) as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == len(j["scaling"]), "results.csv and results.json differ in rows")
    check(rows and KEYS - {"attribution"} <= set(rows[0]), "results.csv lacks a key")
    for scene in SCENES:
        for ext in ("svg", "png"):
            f = os.path.join(out, f"speedup-{scene}.{ext}")
            check(os.path.getsize(f) > 1000 if os.path.exists(f) else False, f"{f} missing")

if problems:
    sys.exit("\n".join(problems))
print("ok")
