# SPDX-License-Identifier: MIT
# Shared by check_experiment.py and check_metg.py: running `tgraph experiment ...` and the
# problems that check() collects (the scripts report them all at the end).
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
