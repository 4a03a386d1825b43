#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes docs/benchmarks.md from the Google Benchmark JSON files of scripts/bench.

Usage: bench_report.py --json-dir DIR --out FILE --command CMD [--wall-s S] [--note TEXT]

Every figure is the median over the repetitions (the `_median` aggregate); cv is the
coefficient of variation over them. The Ratios section divides medians of the same binary
invocation. A section of FILE after the NOTES_MARKER line is kept as it is (hand-written
notes). The file is written to a temporary file in its directory, then renamed.
"""

import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import tempfile

NOTES_MARKER = "<!-- hand-written notes below: scripts/bench keeps them -->"

BINARIES = ["graph_bench", "capture_bench", "samples_bench", "partition_bench",
            "replay_bench", "incremental_bench"]

ABOUT = {
    "graph_bench": "Dependency extraction (`StepGraph::derive_edges`) on synthetic "
                   "physics-like steps of 10^3 to 10^6 tasks, and the trace format: "
                   "`encode_trace` / `read_trace_bytes` (edges derived, as every reader does) "
                   "in memory with structure reuse (repeated structures as reference frames) "
                   "and without (every step a full frame), `write_trace` (with fsync) and "
                   "`read_trace` through a file, on captures of bars64 and falling.",
    "capture_bench": "Recording one task through `Recorder::task` with 0-8 accesses "
                     "(end_step outside the timing), against the uninstrumented call "
                     "(`Mode::kOff`) and the deferred mode; a whole 4096-task step "
                     "with `end_step()`.",
    "samples_bench": "Step time of each scene uninstrumented and captured (`BM_Step`), and "
                     "`BM_CaptureOverhead`: three copies of the scene stepped in lockstep "
                     "(off, captured as `tgraph capture` does, captured with edges derived "
                     "by `end_step()`), so the ratios share the machine's load.",
    "partition_bench": "Each strategy from scratch on step 3 of each scene and K "
                       "(`BM_Partition`, with the simulator's predicted speed-up), sticky "
                       "on an unchanged step (`BM_StickyReuse`), the simulator "
                       "(`BM_Simulate`).",
    "replay_bench": "Signal -> wait between two threads: the raw floor (`BM_SignalWait`, "
                    "one std::atomic, spinning or futex) and through the partition executor "
                    "(`BM_Handoff`, per hand-off, by spin budget before parking); each "
                    "policy on a synthetic bars64-like step (`BM_Policy`); executor cost "
                    "per task instance with empty tasks (`BM_TaskOverhead`), and partition / "
                    "sequential with the two run in turn (`BM_TaskOverheadInTurn`).",
    "incremental_bench": "What a contact change costs on falling, median over the steps "
                         "whose structure changed: graph update, plan rebuild, partitioning "
                         "(METIS, sticky with each fallback), the whole "
                         "rebuild (`BM_FallingRebuild`: edges + partition + plan), and the "
                         "uninstrumented step time (`BM_FallingStep`).",
}

# Counters made with kIsRate | kInvert: Google Benchmark writes seconds; shown in ns.
INVERTED = {"ns_per_task", "ns_per_access", "handoff_ns", "latency_ns"}
# Shown in MB/s (bytes_per_second) or as rates.
RATES = {"bytes_per_second": ("MB/s", 1e-6)}
NOISE = re.compile(r"/(min_time:[0-9.]+|iterations:[0-9]+|repeats:[0-9]+|manual_time|"
                   r"real_time)")


def fmt(v):
    """Three significant digits, with k / M / G from 10^4 up."""
    if v is None:
        return ""
    a = abs(v)
    if a >= 1e9:
        return f"{v / 1e9:.3g}G"
    if a >= 1e6:
        return f"{v / 1e6:.3g}M"
    if a >= 1e4:
        return f"{v / 1e3:.3g}k"
    if a == 0:
        return "0"
    if a >= 100:
        return f"{v:.0f}"
    return f"{v:.3g}"


def clean(name):
    return NOISE.sub("", name)


def load(path):
    """{clean run name: {aggregate name: entry}}, and the context."""
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data.get("benchmarks", []):
        if b.get("error_occurred"):
            runs.setdefault(clean(b["run_name"]), {})["error"] = b
            continue
        if b.get("run_type") == "aggregate":
            runs.setdefault(clean(b["run_name"]), {})[b["aggregate_name"]] = b
        else:  # a single repetition: it is its own median
            runs.setdefault(clean(b["run_name"]), {}).setdefault("median", b)
    return runs, data.get("context", {})


def counters_of(entry):
    skip = {"name", "family_index", "per_family_instance_index", "run_name", "run_type",
            "repetitions", "repetition_index", "threads", "aggregate_name", "aggregate_unit",
            "iterations", "real_time", "cpu_time", "time_unit", "label", "error_occurred",
            "error_message"}
    out = {}
    for k, v in entry.items():
        if k in skip or not isinstance(v, (int, float)):
            continue
        if k in INVERTED:
            v = v * 1e9
        if k in RATES:
            k2, f = RATES[k]
            out[k2] = v * f
        elif k == "items_per_second":
            out["items/s"] = v
        else:
            out[k] = v
    return out


def med(runs, name, key=None):
    """Median of a run's time (in its unit) or of one of its counters; None if absent."""
    r = runs.get(name, {}).get("median")
    if r is None:
        return None
    if key is None:
        return r["real_time"]
    return counters_of(r).get(key)


def run_cmd(args):
    try:
        return subprocess.run(args, capture_output=True, text=True, check=False).stdout
    except OSError:
        return ""


def machine():
    lines = []
    info = {}
    for line in run_cmd(["lscpu"]).splitlines():
        if ":" in line:
            k, v = line.split(":", 1)
            info[k.strip()] = v.strip()
    model = info.get("Model name", "unknown CPU")
    cpus = info.get("CPU(s)", "?")
    cores = info.get("Core(s) per socket", "?")
    sockets = info.get("Socket(s)", "?")
    tpc = info.get("Thread(s) per core", "?")
    lines.append(f"- CPU: {model}, {cpus} CPUs ({sockets} socket(s) x {cores} core(s) x "
                 f"{tpc} thread(s)), {info.get('Vendor ID', '')} "
                 f"{'(virtual machine)' if 'hypervisor' in info.get('Flags', '') else ''}"
                 .rstrip())
    caches = [f"{k.replace(' cache', '')} {info[k]}" for k in ("L1d cache", "L1i cache",
                                                            "L2 cache", "L3 cache") if k in info]
    if not caches:  # lscpu shows none in some VMs: the sizes CPUID reports
        conf = {}
        for line in run_cmd(["getconf", "-a"]).splitlines():
            parts = line.split()
            if len(parts) == 2 and parts[0].endswith("CACHE_SIZE") and parts[1].isdigit():
                conf[parts[0]] = int(parts[1])
        for key, label in (("LEVEL1_DCACHE_SIZE", "L1d"), ("LEVEL1_ICACHE_SIZE", "L1i"),
                           ("LEVEL2_CACHE_SIZE", "L2"), ("LEVEL3_CACHE_SIZE", "L3")):
            if conf.get(key):
                caches.append(f"{label} {conf[key] // 1024} KiB")
        if caches:
            caches[-1] += " (per core as CPUID reports them: `getconf -a`; lscpu shows none)"
    lines.append("- Caches: " + (", ".join(caches) if caches else "not reported"))
    mem = ""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    mem = f"{int(line.split()[1]) / 1024 / 1024:.1f} GiB"
    except OSError:
        pass
    lines.append(f"- Memory: {mem or 'unknown'}; kernel {os.uname().release}")
    gxx = run_cmd(["g++", "--version"]).splitlines()
    if gxx:
        lines.append(f"- Compiler: {gxx[0]} (Release preset, -O3 -march=native)")
    return lines


def table(runs):
    """Markdown tables of one binary, one per family (name up to the first '/')."""
    families = {}
    for name in runs:
        fam = name.split("/", 1)[0]
        families.setdefault(fam, []).append(name)
    out = []
    for fam, names in families.items():
        cols = []
        for n in names:
            r = runs[n].get("median")
            if r is None:
                continue
            for k in counters_of(r):
                if k not in cols:
                    cols.append(k)
        out.append(f"**{fam}**\n")
        out.append("| " + " | ".join(["case", "time (median)", "CPU", "cv"] + cols) + " |")
        out.append("|---" * (4 + len(cols)) + "|")
        for n in names:
            if "error" in runs[n]:
                out.append(f"| {n} | error: {runs[n]['error'].get('error_message', '')} |")
                continue
            r = runs[n].get("median")
            if r is None:
                continue
            cv = runs[n].get("cv")
            cvs = f"{100 * cv['real_time']:.1f} %" if cv else ""
            unit = r.get("time_unit", "ns")
            c = counters_of(r)
            case = n[len(fam) + 1:] if n != fam else "-"
            cells = [case, f"{fmt(r['real_time'])} {unit}", f"{fmt(r['cpu_time'])} {unit}", cvs]
            out.append("| " + " | ".join(cells + [fmt(c.get(k)) for k in cols]) + " |")
        out.append("")
    return out


def ratio(a, b):
    return None if a is None or b is None or b == 0 else a / b


def ratios(all_runs):
    g = all_runs.get("graph_bench", {})
    c = all_runs.get("capture_bench", {})
    s = all_runs.get("samples_bench", {})
    p = all_runs.get("partition_bench", {})
    r = all_runs.get("replay_bench", {})
    i = all_runs.get("incremental_bench", {})
    out = []

    out += ["### Capture on/off", ""]
    out.append("`samples_bench`, `BM_CaptureOverhead/<scene>` (the three modes stepped in "
               "lockstep; median over the repetitions of each repetition's median per-step "
               "ratio):")
    out.append("")
    out.append("| scene | off ms/step | captured ms/step | captured, edges derived, ms/step | "
               "captured / off | with edges / off |")
    out.append("|---|---|---|---|---|---|")
    for scene in ("bars64", "cloth128", "falling"):
        n = f"BM_CaptureOverhead/{scene}"
        if n not in s:
            continue
        o, cap, e = (med(s, n, k) for k in ("off_ms", "capture_ms", "capture_edges_ms"))
        pc, pe = med(s, n, "median_overhead_pct"), med(s, n, "median_edges_overhead_pct")
        out.append(f"| {scene} | {fmt(o)} | {fmt(cap)} | {fmt(e)} | "
                   f"{'' if pc is None else f'{1 + pc / 100:.3f}'} | "
                   f"{'' if pe is None else f'{1 + pe / 100:.3f}'} |")
    off0 = med(c, "BM_RecordTask_Off/accesses:0", "ns_per_task")
    points = [(n, med(c, f"BM_RecordTask_Capture/accesses:{n}", "ns_per_task"))
              for n in (0, 1, 4, 8)]
    points = [(n, v) for n, v in points if v is not None]
    if off0 is not None and len(points) >= 2:
        # Least-squares line through (accesses, ns per task): intercept = per task, slope =
        # per access.
        mx = sum(n for n, _ in points) / len(points)
        my = sum(v for _, v in points) / len(points)
        slope = (sum((n - mx) * (v - my) for n, v in points) /
                 sum((n - mx) ** 2 for n, _ in points))
        icpt = my - slope * mx
        out.append("")
        out.append(f"`capture_bench`: recording a task costs {fmt(icpt - off0)} ns over the "
                   f"uninstrumented call ({fmt(icpt)} ns, the intercept of a least-squares line "
                   f"through `BM_RecordTask_Capture/accesses:{{0,1,4,8}}`, minus "
                   f"`BM_RecordTask_Off/accesses:0`, {fmt(off0)} ns), plus {fmt(slope)} ns "
                   f"per access (its slope).")
    out.append("")

    out += ["### Sticky versus a full METIS", ""]
    out.append("After a contact change (`incremental_bench`, `BM_FallingPartition`: median "
               "over the falling steps whose structure changed of each step's partitioning "
               "time):")
    out.append("")
    out.append("| K | METIS us | sticky (refine fallback, the default) us | / METIS | "
               "sticky-fresh us | / METIS | sticky-repartition us | / METIS |")
    out.append("|---|---|---|---|---|---|---|---|")
    for k in (2, 4, 8):
        m = med(i, f"BM_FallingPartition/metis/k:{k}", "median_us")
        if m is None:
            continue
        cells = [str(k), fmt(m)]
        for v in ("sticky", "sticky-fresh", "sticky-repartition"):
            x = med(i, f"BM_FallingPartition/{v}/k:{k}", "median_us")
            cells += [fmt(x), fmt(ratio(x, m))]
        out.append("| " + " | ".join(cells) + " |")
    out.append("")
    out.append("On an unchanged step (`partition_bench`, `BM_StickyReuse` against "
               "`BM_Partition/<scene>/metis`):")
    out.append("")
    out.append("| scene | K | METIS us | sticky reuse us | sticky / METIS |")
    out.append("|---|---|---|---|---|")
    for name in p:
        mm = re.match(r"BM_Partition/([^/]+)/metis/k:(\d+)$", name)
        if not mm:
            continue
        scene, k = mm.groups()
        m = med(p, name)
        st = med(p, f"BM_StickyReuse/{scene}/k:{k}")
        out.append(f"| {scene} | {k} | {fmt(m)} | {fmt(st)} | {fmt(ratio(st, m))} |")
    out.append("")

    out += ["### Executor overhead per task", ""]
    seq_row = r.get("BM_TaskOverhead/sequential/threads:1", {}).get("median")
    seq_ns = med(r, "BM_TaskOverhead/sequential/threads:1", "ns_per_task")
    instances = ""
    if seq_row is not None and seq_ns:
        scale = {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}[seq_row.get("time_unit", "ns")]
        instances = f"{seq_row['real_time'] * scale / seq_ns:,.0f} task instances at one thread, "
    out.append("`replay_bench`, `BM_TaskOverhead/<policy>/threads:N` (a bars64-like step, "
               f"{instances}empty bodies):")
    out.append("")
    out.append("| policy | threads | ns per task | / partition at the same threads |")
    out.append("|---|---|---|---|")
    for t in (1, 2):
        base = med(r, f"BM_TaskOverhead/partition/threads:{t}", "ns_per_task")
        for pol in ("sequential", "partition", "worksteal", "barrier", "omp-tasks", "starpu"):
            v = med(r, f"BM_TaskOverhead/{pol}/threads:{t}", "ns_per_task")
            if v is None:
                continue
            out.append(f"| {pol} | {t} | {fmt(v)} | {fmt(ratio(v, base))} |")
    if not any(n.startswith("BM_TaskOverhead/starpu") for n in r):
        out.append("")
        out.append("(This build has no StarPU: `starpu` is not measured.)")
    turns = [(t, med(r, f"BM_TaskOverheadInTurn/threads:{t}", "ratio"),
              med(r, f"BM_TaskOverheadInTurn/threads:{t}", "ratio_p10"),
              med(r, f"BM_TaskOverheadInTurn/threads:{t}", "ratio_p90")) for t in (1, 2)]
    if any(v is not None for _, v, _, _ in turns):
        out.append("")
        out.append("Partition / sequential with the two executors run in turn "
                   "(`BM_TaskOverheadInTurn/threads:N`: blocks of 200 steps each, the median "
                   "of 40 block pairs' ratios, robust to a change of the host's speed between "
                   "repetitions): " + "; ".join(
                       f"{t} thread{'s' if t > 1 else ''} {fmt(v)} (p10 {fmt(lo)}, p90 {fmt(hi)})"
                       for t, v, lo, hi in turns if v is not None) + ".")
        quiet = [(t, med(r, f"BM_TaskOverheadInTurn/threads:{t}", "ratio_quiet"),
                  med(r, f"BM_TaskOverheadInTurn/threads:{t}", "quiet_pairs")) for t in (1, 2)]
        if any(n is not None for _, _, n in quiet):
            out.append("Over the block pairs whose host probes, before and after the pair, found "
                       "both cores at the same speed, the first as fast beside the second as "
                       "alone, and near its fastest (a quiet machine): " + "; ".join(
                           f"{t} thread{'s' if t > 1 else ''} "
                           + (f"{fmt(v)} ({n:.0f} pairs)" if n else "no quiet pair")
                           for t, v, n in quiet if n is not None) + ".")
        apart = [(t, med(r, f"BM_TaskOverheadInTurn/threads:{t}", "ratio_uncombined"),
                  med(r, f"BM_TaskOverheadInTurn/threads:{t}", "ratio_quiet_uncombined"))
                 for t in (1, 2)]
        if any(v is not None for _, v, _ in apart):
            out.append("Partition without combined reductions (`PartitionOptions::combine` off, "
                       "timed in the same iterations, a third block): " + "; ".join(
                           f"{t} thread{'s' if t > 1 else ''} {fmt(v)}"
                           + (f" (quiet pairs: {fmt(q)})" if q else "")
                           for t, v, q in apart if v is not None) + ".")
        def probe(key):
            return med(r, "BM_TaskOverheadInTurn/threads:2", key)
        if probe("core_speed") is not None:
            out.append("The host during the 2-thread run (probed after each block pair): "
                       f"second core's speed over the first's {fmt(probe('core_speed'))} (p10 "
                       f"{fmt(probe('core_speed_p10'))}, p90 {fmt(probe('core_speed_p90'))}; "
                       f"1 on a quiet machine), hand-off {fmt(probe('probe_handoff_ns'))} ns.")
    out.append("")

    out += ["### Signal -> wait", ""]
    spin = med(r, "BM_SignalWait/spin", "latency_ns")
    futex = med(r, "BM_SignalWait/futex", "latency_ns")
    h = {sp: med(r, f"BM_Handoff/work_ns:0/spin_ns:{sp}", "handoff_ns") for sp in (0, 5000, 50000)}
    out.append("| path | ns per signal -> wait |")
    out.append("|---|---|")
    if spin is not None:
        out.append(f"| raw std::atomic, spinning (`BM_SignalWait/spin`) | {fmt(spin)} |")
    if futex is not None:
        out.append(f"| raw std::atomic::wait / notify_one (`BM_SignalWait/futex`) | {fmt(futex)} |")
    for sp, v in h.items():
        if v is not None:
            out.append(f"| partition executor, spin budget {sp} ns "
                       f"(`BM_Handoff/work_ns:0/spin_ns:{sp}`) | {fmt(v)} |")
    out.append("")

    out += ["### Graph rebuild after a contact change / step time", ""]
    step = med(i, "BM_FallingStep", "median_ms")
    step_c = med(i, "BM_FallingStep", "changes_median_ms")
    out.append(f"`incremental_bench`: an uninstrumented falling step takes {fmt(step)} ms "
               f"(median over the run; {fmt(step_c)} ms at the contact changes). The paper: "
               "graph update about 30 ms, about one step.")
    out.append("")
    out.append("| rebuild | K | edges us | partition us | plan us | total us | total / step |")
    out.append("|---|---|---|---|---|---|---|")
    for kind in ("incremental", "scratch"):
        for k in (2, 4, 8):
            n = f"BM_FallingRebuild/{kind}/k:{k}"
            if n not in i:
                continue
            tot = med(i, n, "median_us")
            out.append(f"| {kind} | {k} | {fmt(med(i, n, 'edges_median_us'))} | "
                       f"{fmt(med(i, n, 'partition_median_us'))} | "
                       f"{fmt(med(i, n, 'plan_median_us'))} | {fmt(tot)} | "
                       f"{fmt(ratio(tot, None if step is None else step * 1000))} |")
    out.append("")
    out.append("(incremental: `EdgeDeriver`, sticky from the previous step's sticky assignment, "
               "the executor's incremental plan update; scratch: `derive_edges`, METIS afresh, "
               "the plan from scratch. Each part and the total are medians over the changes, "
               "so the parts need not add up to the total.)")
    out.append("")

    out += ["### Dependency extraction and traces", ""]
    rows = []
    for name in g:
        mm = re.match(r"BM_DeriveEdges/tasks:(\d+)$", name)
        if mm:
            rows.append((int(mm.group(1)), med(g, name, "accesses_per_s"),
                         med(g, name, "tasks_per_s")))
    if rows:
        out.append("| tasks | accesses/s | tasks/s |")
        out.append("|---|---|---|")
        for n, a, t in sorted(rows):
            out.append(f"| {n} | {fmt(a)} | {fmt(t)} |")
        out.append("")
    out.append("| trace | bytes/task with reuse | without | ratio | decode tasks/s with reuse "
               "| without | ratio |")
    out.append("|---|---|---|---|---|---|---|")
    for scene in ("bars64", "falling"):
        br = med(g, f"BM_TraceEncode/{scene}/reuse", "bytes_per_task")
        bf = med(g, f"BM_TraceEncode/{scene}/full", "bytes_per_task")
        dr = med(g, f"BM_TraceDecode/{scene}/reuse", "items/s")
        df = med(g, f"BM_TraceDecode/{scene}/full", "items/s")
        if br is None:
            continue
        out.append(f"| {scene} | {fmt(br)} | {fmt(bf)} | {fmt(ratio(bf, br))} | {fmt(dr)} | "
                   f"{fmt(df)} | {fmt(ratio(dr, df))} |")
    out.append("")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json-dir", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--command", required=True)
    ap.add_argument("--wall-s", type=float)
    ap.add_argument("--note", default="")
    a = ap.parse_args()

    all_runs, contexts = {}, {}
    for b in BINARIES:
        path = os.path.join(a.json_dir, b + ".json")
        if not os.path.exists(path) or os.path.getsize(path) == 0:
            continue
        try:
            all_runs[b], contexts[b] = load(path)
        except (OSError, ValueError) as e:
            print(f"bench_report.py: {path}: not a Google Benchmark JSON file ({e})",
                  file=sys.stderr)
            sys.exit(2)
    if not all_runs:
        print(f"bench_report.py: {a.json_dir}: no benchmark JSON file "
              f"(expected {', '.join(b + '.json' for b in BINARIES)})", file=sys.stderr)
        sys.exit(2)

    notes = ""
    if os.path.exists(a.out):
        with open(a.out) as f:
            old = f.read()
        if NOTES_MARKER in old:
            notes = old.split(NOTES_MARKER, 1)[1]

    first = next(iter(contexts.values()))
    date = first.get("date", datetime.datetime.now().isoformat())
    commit = run_cmd(["git", "-C", os.path.dirname(os.path.abspath(a.out)), "rev-parse",
                      "--short", "HEAD"]).strip()
    lines = ["# Benchmarks", "",
             "Written by `scripts/bench` from the Google Benchmark JSON of the binaries under "
             "`bench/` (one per module); do not edit above the notes marker, run it again. "
             "Every figure is the **median** over the repetitions; `cv` is their coefficient "
             "of variation. Ratios divide medians measured in the same binary invocation.",
             "",
             "## Machine and run", ""]
    lines += machine()
    loads = [ctx.get("load_avg", [None])[0] for ctx in contexts.values()]
    loads = [f"{x:.1f}" for x in loads if x is not None]
    lines.append(f"- Date: {date}; tgraph commit {commit or 'unknown'}")
    lines.append(f"- Command: `{a.command}`" +
                 (f" ({a.wall_s:.0f} s wall, build included)" if a.wall_s else ""))
    times = os.path.join(a.json_dir, "times.txt")
    if os.path.exists(times):
        with open(times) as f:
            parts = [line.split() for line in f if len(line.split()) == 2]
        lines.append("- Wall time per binary: " + ", ".join(f"{b} {t} s" for b, t in parts))
    lines.append(f"- Google Benchmark library build type: {first.get('library_build_type', '?')} "
                 "(Debian's package; it affects the framework's bookkeeping, not the measured "
                 "code, which is built in Release)")
    if loads:
        lines.append(f"- Load average (1 min) as each binary started: {', '.join(loads)}")
    if a.note:
        lines.append(f"- Conditions: {a.note}")
    lines.append("")

    lines.append("## Ratios")
    lines.append("")
    lines += ratios(all_runs)

    lines.append("## All benchmarks")
    lines.append("")
    for b in BINARIES:
        if b not in all_runs:
            continue
        lines.append(f"### {b}")
        lines.append("")
        lines.append(ABOUT[b])
        lines.append("")
        lines += table(all_runs[b])

    lines.append(NOTES_MARKER + (notes if notes else "\n"))
    text = "\n".join(lines)
    if not text.endswith("\n"):
        text += "\n"
    out_dir = os.path.dirname(os.path.abspath(a.out))
    os.makedirs(out_dir, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=out_dir, prefix=".benchmarks.", suffix=".md.tmp")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, a.out)
    except BaseException:
        os.unlink(tmp)
        raise
    print(f"bench_report.py: wrote {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
