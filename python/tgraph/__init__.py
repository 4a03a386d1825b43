# SPDX-License-Identifier: MIT
"""tgraph from Python: read traces, per-step metrics and tables, partition and evaluate.

    import tgraph
    t = tgraph.read_trace("b.tgt")
    print(t.steps, t.metrics(0).parallelism)
    a = tgraph.partition(t, "metis", 4)
    print(tgraph.evaluate(t, a)["predicted_speedup"])

Tables (Step.tasks(), .edges(), .data(), .accesses(), .loops()) are dicts of equal-length
lists: pandas.DataFrame(step.tasks()) makes a data frame. See docs/python.md.
"""
import gzip as _gzip
import json as _json

from . import _tgraph
from ._tgraph import (Assignment, Error, Metrics, Step, Trace, UnitMetrics, __version__,
                      read_trace, strategies)

__all__ = ["Assignment", "Error", "Metrics", "Step", "Trace", "UnitMetrics", "__version__",
           "evaluate",
           "partition", "read_assignment", "read_replay", "read_trace",
           "strategies", "summary"]


def summary(trace, name="", unit_cost=False):
    """What `tgraph info --json` prints for this trace, as a dict (same keys and values);
    with unit_cost=True what `tgraph info --unit-cost --json` prints (span_tasks...)."""
    return _json.loads(trace._summary_json(name, unit_cost))


def partition(trace, method, k, imbalance=1.03, seed=0, sticky_base="metis"):
    """Partitions every step of `trace` over `k` processors with strategy `method`
    (tgraph.strategies() lists them). Returns an Assignment whose `stats` is what
    `tgraph partition --json` prints (a dict)."""
    a, stats = _tgraph._partition(trace, method, k, imbalance, seed, sticky_base)
    a.stats = _json.loads(stats)
    return a


def read_assignment(path, trace):
    """Reads a .tga file (`tgraph partition -o`) and checks that it fits `trace`."""
    a = _tgraph._read_assignment(path, trace)
    a.stats = None
    return a


def evaluate(trace, assignment, model="calibrated", calibration=""):
    """What `tgraph evaluate --json` prints, as a dict: cut, imbalance, signals, waits,
    migrations, predicted makespan and speed-up (totals, and "per_step")."""
    return _json.loads(_tgraph._evaluate(trace, assignment, model, calibration))


def read_replay(path):
    """A replay result (`tgraph replay --json > R.json`, `tgraph run --json`) or timeline
    (`tgraph replay --timeline R.json`, gzip-compressed columns: docs/trace-format.md), as a
    dict."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:2] == b"\x1f\x8b":
        data = _gzip.decompress(data)
    return _json.loads(data.decode("utf-8"))
