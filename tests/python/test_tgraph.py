# SPDX-License-Identifier: MIT
"""The Python module against the command line on the same files: every figure the module
gives is checked against `tgraph info --json`, `tgraph partition --json` and
`tgraph evaluate --json`, or against the file's own content."""
import json
import os
import subprocess

import pytest

import tgraph

TGRAPH = os.environ.get("TGRAPH_BIN", "tgraph")
DATA = os.environ.get("TGRAPH_TEST_DATA", os.path.join(os.path.dirname(__file__), "..", "data"))


def cli(*args):
    out = subprocess.run([TGRAPH, *map(str, args)], check=True, capture_output=True, text=True)
    return out.stdout


def cli_json(*args):
    return json.loads(cli(*args, "--json"))


@pytest.fixture(scope="module")
def fig2(tmp_path_factory):
    path = tmp_path_factory.mktemp("traces") / "fig2.tgt"
    cli("capture", "--scene", "fig2", "--steps", 4, "-o", path)
    return str(path)


@pytest.fixture(scope="module")
def bars(tmp_path_factory):
    path = tmp_path_factory.mktemp("traces") / "bars64.tgt"
    cli("capture", "--scene", "bars64", "--steps", 2, "-o", path)
    return str(path)


@pytest.mark.parametrize("name", ["fig2", "bars"])
def test_steps_and_metrics_equal_tgraph_info(name, request):
    path = request.getfixturevalue(name)
    info = cli_json("info", path)
    t = tgraph.read_trace(path)
    assert t.steps == info["steps"] == len(t)
    assert t.header["scene"] == info["scene"]
    assert t.header["engine"] == info["engine"]
    for s, row in enumerate(info["per_step"]):
        m = t.metrics(s)
        assert m.tasks == row["tasks"]
        assert m.edges == row["edges"]
        assert m.data == row["data"]
        assert m.loops == row["loops"]
        assert m.work_ns == row["work_ns"]
        assert m.span_ns == row["span_ns"]
        assert m.parallelism == pytest.approx(row["parallelism"], rel=1e-12)
        step = t.step(s)
        assert step.num_tasks == row["tasks"]
        assert step.num_edges == row["edges"]
        assert step.num_data == row["data"]
        assert step.loops()["iterations"] == row["loop_iterations"]
        assert step.structural_hash == row["structure"]
        assert step.host_ns == row["host_ns"]
    # The module's summary is the command line's JSON, figure for figure.
    mine = tgraph.summary(t, path)
    assert mine == info


def test_tables_are_columns_of_equal_length_consistent_with_the_metrics(bars):
    t = tgraph.read_trace(bars)
    step = t.step(1)
    m = t.metrics(1)
    tasks, edges, data = step.tasks(), step.edges(), step.data()
    assert len({len(col) for col in tasks.values()}) == 1
    assert len(tasks["id"]) == m.tasks
    assert len(edges["from"]) == m.edges
    assert len(data["name"]) == m.data
    # work = sum of cost x runs (what `tgraph info` calls work)
    assert sum(c * r for c, r in zip(tasks["cost_ns"], tasks["runs"])) == m.work_ns
    assert set(edges["kind"]) <= {"RAW", "WAR", "WAW"}
    assert all(f < step.num_tasks and to < step.num_tasks for f, to in zip(edges["from"], edges["to"]))
    # per-kind counts from the table equal the metrics'
    counts = {}
    for k in tasks["kind"]:
        counts[k] = counts.get(k, 0) + 1
    assert counts == m.per_kind
    accesses = step.accesses()
    assert len(accesses["task"]) == sum(tasks["accesses"])
    assert set(accesses["mode"]) <= {"R", "W", "RW", "CW"}
    # bars64 has one CG loop whose iterations are the runs of its body tasks
    loops = step.loops()
    assert len(loops["first"]) == 1
    first, last = loops["first"][0], loops["last"][0]
    assert all(tasks["runs"][i] == loops["iterations"][0] for i in range(first, last))
    assert max(step.earliest_finish()) == m.span_ns


def test_partition_and_evaluate_equal_the_command_line(bars, tmp_path):
    t = tgraph.read_trace(bars)
    a = tgraph.partition(t, "owner", 4)
    assert a.k == 4 and a.method == "owner" and a.steps == t.steps
    procs = a.proc(0)
    assert len(procs) == t.step(0).num_tasks and set(procs) == {0, 1, 2, 3}
    assert a.stats["steps"] == t.steps
    # the same assignment written by the module and by the command line
    mine, theirs = tmp_path / "mine.tga", tmp_path / "theirs.tga"
    a.write(str(mine), t)
    cli("partition", bars, "--method", "owner", "-k", 4, "-o", theirs)
    b = tgraph.read_assignment(str(theirs), t)
    assert [b.proc(s) for s in range(b.steps)] == [a.proc(s) for s in range(a.steps)]
    report = tgraph.evaluate(t, a, model="ideal")
    cli_report = cli_json("evaluate", bars, mine, "--model", "ideal")
    for key in ("predicted_makespan_ns", "cut_bytes", "signals", "waits", "imbalance",
                "predicted_speedup", "migrated_tasks", "k", "steps"):
        assert report[key] == cli_report[key], key
    assert report["k"] == 4 and report["predicted_speedup"] > 1.0
    assert len(report["per_step"]) == t.steps


def test_bad_input_raises_a_value_error_naming_the_file(tmp_path):
    bad = tmp_path / "bad.tgt"
    bad.write_bytes(b"TGTR\x01\x00\x00\x00garbage")
    with pytest.raises(ValueError, match="bad.tgt"):
        tgraph.read_trace(str(bad))
    with pytest.raises(ValueError):
        tgraph.read_trace(str(tmp_path / "missing.tgt"))


def test_out_of_range_step_and_unknown_method_are_errors(fig2):
    t = tgraph.read_trace(fig2)
    with pytest.raises(IndexError):
        t.metrics(t.steps)
    assert t.step(-1).index == t.steps - 1
    with pytest.raises(ValueError, match="unknown method"):
        tgraph.partition(t, "no-such-method", 2)
    assert "metis" in tgraph.strategies()


def test_stg_import_keeps_the_stated_critical_path(tmp_path):
    # STG rand0000 (50 tasks): the file states its critical path; imported at 1000 ns per
    # unit, the span the module computes is that length.
    src = os.path.join(DATA, "stg", "50", "rand0000.stg")
    out = tmp_path / "g.tgt"
    imported = cli_json("import", "--format", "stg", src, "-o", out)
    t = tgraph.read_trace(str(out))
    assert t.steps == 1
    assert t.metrics(0).tasks == imported["tasks"]
    assert t.metrics(0).span_ns == imported["cp_length"] * 1000


def test_unit_metrics_count_tasks_as_info_unit_cost_does(fig2):
    # Figure 2: reset -> addForce -> updateVelocity -> updatePosition is the longest chain
    # (4 tasks) of 9 tasks per step, whatever the measured costs.
    info = cli_json("info", fig2, "--unit-cost")
    t = tgraph.read_trace(fig2)
    for s, row in enumerate(info["per_step"]):
        u = t.unit_metrics(s)
        assert u.span_tasks == row["span_tasks"] == 4
        assert u.work_tasks == row["work_tasks"] == 9
        assert u.parallelism == pytest.approx(9 / 4)
        assert t.step(s).unit_metrics().span_tasks == 4
    assert info["span_tasks"] == 4 * t.steps
    assert tgraph.summary(t, fig2, unit_cost=True) == info


def test_read_replay_returns_the_json_of_tgraph_replay(fig2, tmp_path):
    timeline = tmp_path / "r.json"
    out = tmp_path / "replay.json"
    out.write_text(cli("replay", fig2, "--threads", 1, "--policy", "sequential", "--repeat", 1,
                       "--timeline", timeline, "--json"))
    r = tgraph.read_replay(str(out))
    assert r["threads"] == 1 and r["policy"] == "sequential"
    assert r["steps"] == len(r["per_step"]) == tgraph.read_trace(fig2).steps
    assert isinstance(tgraph.read_replay(str(timeline)), (dict, list))
