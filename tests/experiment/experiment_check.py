# SPDX-License-Identifier: MIT
# Shared by check_experiment.py, check_metg.py and check_scaling.py: running `tgraph
# experiment ...` and the problems that check() collects (the scripts report them all at the
# end).
import json
import os
import subprocess
import sys

problems = []


def check(ok, what):
    """Records `what` as a problem unless `ok`; returns `ok`."""
    if not ok:
        problems.append(what)
    return ok


def run_experiment(tgraph, args, timeout):
    """Runs `tgraph experiment ARGS`; exits with its output when it fails."""
    run = subprocess.run([tgraph, "experiment", *args], capture_output=True, text=True,
                         timeout=timeout)
    if run.returncode != 0:
        sys.exit(f"exit {run.returncode}\nstdout:\n{run.stdout}\nstderr:\n{run.stderr}")
    return run


def run_quick_json(tgraph, name, out, timeout):
    """Runs `tgraph experiment NAME --quick --out OUT --json`; returns OUT/results.json,
    checked to hold the records printed on stdout (its key NAME)."""
    run = run_experiment(tgraph, [name, "--quick", "--out", out, "--json"], timeout)
    j = json.load(open(os.path.join(out, "results.json")))
    check(json.loads(run.stdout)[name] == j[name], f"--json and results.json disagree on {name}")
    return j
