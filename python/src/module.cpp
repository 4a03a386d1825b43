// SPDX-License-Identifier: MIT
// `import tgraph`: traces, per-step metrics and tables, partitioning and offline evaluation
// from Python (pybind11). Tables are dicts of equal-length lists (pandas.DataFrame(d) takes
// them); JSON reports are parsed by the package (python/tgraph/__init__.py).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/summary.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/compare.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace py = pybind11;

namespace tgraph::python {
namespace {

// A trace shared by the Step views taken from it (a Step keeps its trace alive).
using TracePtr = std::shared_ptr<Trace>;

struct StepView {
  TracePtr trace;
  std::size_t index = 0;
  const StepGraph& g() const { return trace->steps[index]; }
};

const StepGraph& step_of(const TracePtr& t, std::int64_t i) {
  const auto n = static_cast<std::int64_t>(t->steps.size());
  if (i < 0) i += n;
  if (i < 0 || i >= n)
    throw py::index_error("step " + std::to_string(i) + " out of range (trace has " +
                          std::to_string(n) + " steps)");
  return t->steps[static_cast<std::size_t>(i)];
}

std::size_t index_of(const TracePtr& t, std::int64_t i) {
  return static_cast<std::size_t>(&step_of(t, i) - t->steps.data());
}

py::dict tasks_table(const StepGraph& g) {
  std::vector<std::uint32_t> id, object, loop, accesses;
  std::vector<std::string> kind, object_name;
  std::vector<std::uint64_t> cost, runs, key;
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const Task& task = g.tasks[t];
    id.push_back(t);
    kind.push_back(g.kind_name(t));
    object.push_back(task.object);
    object_name.push_back(task.object < g.objects.size() ? g.objects[task.object].name : "");
    cost.push_back(task.cost_ns);
    runs.push_back(g.runs(t));
    loop.push_back(task.loop);
    key.push_back(task.key);
    accesses.push_back(task.access_count);
  }
  py::dict d;
  d["id"] = id;
  d["kind"] = kind;
  d["object"] = object;
  d["object_name"] = object_name;
  d["cost_ns"] = cost;
  d["runs"] = runs;
  d["loop"] = loop;  // 4294967295: not in a loop
  d["key"] = key;
  d["accesses"] = accesses;
  return d;
}

py::dict edges_table(const StepGraph& g) {
  std::vector<std::uint32_t> from, to, datum;
  std::vector<std::string> kind;
  std::vector<bool> carried;
  for (const auto* list : {&g.edges, &g.carried_edges})
    for (const Edge& e : *list) {
      from.push_back(e.from);
      to.push_back(e.to);
      datum.push_back(e.datum);
      kind.emplace_back(to_string(e.kind));
      carried.push_back(list == &g.carried_edges);
    }
  py::dict d;
  d["from"] = from;
  d["to"] = to;
  d["datum"] = datum;
  d["kind"] = kind;
  d["carried"] = carried;
  return d;
}

py::dict data_table(const StepGraph& g) {
  std::vector<std::uint32_t> id, object;
  std::vector<std::string> name;
  std::vector<std::uint64_t> bytes;
  for (DatumId i = 0; i < g.data.size(); ++i) {
    id.push_back(i);
    name.push_back(g.data[i].name);
    object.push_back(g.data[i].object);
    bytes.push_back(g.data[i].bytes);
  }
  py::dict d;
  d["id"] = id;
  d["name"] = name;
  d["object"] = object;  // 4294967295: shared datum
  d["bytes"] = bytes;
  return d;
}

py::dict accesses_table(const StepGraph& g) {
  std::vector<std::uint32_t> task, datum;
  std::vector<std::string> mode;
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    for (const Access& a : g.accesses_of(t)) {
      task.push_back(t);
      datum.push_back(a.datum);
      mode.emplace_back(to_string(a.mode));
    }
  py::dict d;
  d["task"] = task;
  d["datum"] = datum;
  d["mode"] = mode;
  return d;
}

py::dict loops_table(const StepGraph& g) {
  std::vector<std::uint32_t> first, last, iterations, max_iterations, condition;
  for (const Loop& l : g.loops) {
    first.push_back(l.first);
    last.push_back(l.last);
    iterations.push_back(l.iterations);
    max_iterations.push_back(l.max_iterations);
    condition.push_back(l.condition);
  }
  py::dict d;
  d["first"] = first;
  d["last"] = last;
  d["iterations"] = iterations;
  d["max_iterations"] = max_iterations;
  d["condition"] = condition;
  return d;
}

partition::Options partition_options(double imbalance, std::uint64_t seed,
                                     const std::string& sticky_base) {
  partition::Options o;
  o.imbalance = imbalance;
  o.seed = seed;
  o.sticky_base = sticky_base;
  return o;
}

}  // namespace
}  // namespace tgraph::python

PYBIND11_MODULE(_tgraph, m) {
  using namespace tgraph;
  using namespace tgraph::python;
  m.doc() = "tgraph: task graphs of physics simulation steps (traces, metrics, partitions)";
  m.attr("__version__") = TGRAPH_VERSION;

  // Bad input (tgraph::InputError / UsageError) -> ValueError with the one-line reason.
  py::register_exception<Error>(m, "Error", PyExc_ValueError);

  py::class_<Metrics>(m, "Metrics", "Size, work, span and parallelism of one step")
      .def_readonly("tasks", &Metrics::tasks)
      .def_readonly("edges", &Metrics::edges, "intra-step + loop-carried edges")
      .def_readonly("data", &Metrics::data)
      .def_readonly("loops", &Metrics::loops)
      .def_readonly("loop_iterations", &Metrics::loop_iterations, "sum over loops")
      .def_readonly("work_ns", &Metrics::work_ns, "sum of cost x runs")
      .def_readonly("span_ns", &Metrics::span_ns, "critical path with loops unrolled")
      .def_readonly("parallelism", &Metrics::parallelism, "work / span")
      .def_readonly("per_kind", &Metrics::per_kind, "task count per kind")
      .def("__repr__", [](const Metrics& x) {
        return "Metrics(tasks=" + std::to_string(x.tasks) + ", edges=" + std::to_string(x.edges) +
               ", work_ns=" + std::to_string(x.work_ns) + ", span_ns=" + std::to_string(x.span_ns) +
               ", parallelism=" + std::to_string(x.parallelism) + ")";
      });

  py::class_<UnitMetrics>(m, "UnitMetrics",
                          "Work and span of one step in tasks (every task run costs 1)")
      .def_readonly("work_tasks", &UnitMetrics::work_tasks,
                    "task runs (a loop body task once per iteration)")
      .def_readonly("span_tasks", &UnitMetrics::span_tasks,
                    "hop count of the critical path, loops unrolled")
      .def_readonly("parallelism", &UnitMetrics::parallelism, "work_tasks / span_tasks")
      .def("__repr__", [](const UnitMetrics& x) {
        return "UnitMetrics(work_tasks=" + std::to_string(x.work_tasks) +
               ", span_tasks=" + std::to_string(x.span_tasks) +
               ", parallelism=" + std::to_string(x.parallelism) + ")";
      });

  py::class_<StepView>(m, "Step", "One step's task graph (a view into its trace)")
      .def_property_readonly("index", [](const StepView& s) { return s.index; })
      .def_property_readonly("num_tasks", [](const StepView& s) { return s.g().tasks.size(); })
      .def_property_readonly(
          "num_edges",
          [](const StepView& s) { return s.g().edges.size() + s.g().carried_edges.size(); },
          "intra-step + loop-carried edges (as Metrics.edges and tgraph info)")
      .def_property_readonly("num_data", [](const StepView& s) { return s.g().data.size(); })
      .def_property_readonly("num_loops", [](const StepView& s) { return s.g().loops.size(); })
      .def_property_readonly("kinds", [](const StepView& s) { return s.g().kinds; })
      .def_property_readonly("objects",
                             [](const StepView& s) {
                               std::vector<std::string> names;
                               for (const ObjectInfo& o : s.g().objects) names.push_back(o.name);
                               return names;
                             })
      .def_property_readonly("contacts",
                             [](const StepView& s) {
                               std::vector<std::pair<ObjectId, ObjectId>> pairs;
                               for (const Contact& c : s.g().contacts) pairs.emplace_back(c.a, c.b);
                               return pairs;
                             })
      .def_property_readonly(
          "host_ns", [](const StepView& s) { return s.g().host_ns; },
          "engine time outside the step's tasks, before them (collision detection); 0 in "
          "version 1 traces")
      .def_property_readonly("structural_hash",
                             [](const StepView& s) { return s.g().structural_hash(); })
      .def("metrics", [](const StepView& s) { return compute_metrics(s.g()); })
      .def(
          "unit_metrics", [](const StepView& s) { return compute_unit_metrics(s.g()); },
          "work and span in tasks (tgraph info --unit-cost)")
      .def(
          "tasks", [](const StepView& s) { return tasks_table(s.g()); },
          "dict of columns: id, kind, object, object_name, cost_ns, runs, loop, key, accesses")
      .def(
          "edges", [](const StepView& s) { return edges_table(s.g()); },
          "dict of columns: from, to, datum, kind (RAW/WAR/WAW), carried (loop-carried)")
      .def(
          "data", [](const StepView& s) { return data_table(s.g()); },
          "dict of columns: id, name, object, bytes")
      .def(
          "accesses", [](const StepView& s) { return accesses_table(s.g()); },
          "dict of columns: task, datum, mode (R/W/RW/CW)")
      .def(
          "loops", [](const StepView& s) { return loops_table(s.g()); },
          "dict of columns: first, last, iterations, max_iterations, condition")
      .def(
          "earliest_finish", [](const StepView& s) { return earliest_finish(s.g()); },
          "earliest finish (ns) of every task under unlimited processors; max = span")
      .def("__repr__", [](const StepView& s) {
        return "Step(" + std::to_string(s.index) + ", tasks=" + std::to_string(s.g().tasks.size()) +
               ")";
      });

  py::class_<Trace, TracePtr>(m, "Trace", "A captured trace: header and step graphs")
      .def_property_readonly(
          "steps", [](const Trace& t) { return t.steps.size(); }, "number of steps")
      .def_property_readonly("header",
                             [](const Trace& t) {
                               py::dict d;
                               d["scene"] = t.header.scene;
                               d["engine"] = t.header.engine;
                               d["machine"] = t.header.machine;
                               d["tgraph_version"] = t.header.tgraph_version;
                               return d;
                             })
      .def("__len__", [](const Trace& t) { return t.steps.size(); })
      .def(
          "step",
          [](const TracePtr& t, std::int64_t i) {
            return StepView{t, index_of(t, i)};
          },
          py::arg("i"))
      .def(
          "metrics",
          [](const TracePtr& t, std::int64_t i) { return compute_metrics(step_of(t, i)); },
          py::arg("i"), "Metrics of step i")
      .def(
          "unit_metrics",
          [](const TracePtr& t, std::int64_t i) { return compute_unit_metrics(step_of(t, i)); },
          py::arg("i"), "UnitMetrics of step i: work and span in tasks")
      .def("_summary_json", [](const Trace& t, const std::string& name, bool unit_cost) {
        return trace_summary_json(summarize_trace(t, SummaryOptions{.unit_cost = unit_cost}), name);
      });

  m.def(
      "read_trace",
      [](const std::string& path, bool recover) {
        ReadOptions o;
        o.recover = recover;
        TracePtr t;
        {
          py::gil_scoped_release release;
          t = std::make_shared<Trace>(read_trace(path, o));
        }
        return t;
      },
      py::arg("path"), py::arg("recover") = false,
      "Reads a .tgt trace (edges derived). Malformed input raises tgraph.Error.");

  py::class_<TraceAssignment>(m, "Assignment", py::dynamic_attr(),
                              "One assignment per step of a trace")
      .def_readonly("method", &TraceAssignment::method)
      .def_readonly("k", &TraceAssignment::k)
      .def_readonly("partition_ms", &TraceAssignment::partition_ms)
      .def_property_readonly("steps", [](const TraceAssignment& a) { return a.steps.size(); })
      .def(
          "proc",
          [](const TraceAssignment& a, std::size_t s) {
            if (s >= a.steps.size()) throw py::index_error("step out of range");
            return a.steps[s].proc;
          },
          py::arg("step"), "processor of every task of step `step`")
      .def(
          "write",
          [](const TraceAssignment& a, const std::string& path, const Trace& t) {
            partition::write_assignment(path, a, t);
          },
          py::arg("path"), py::arg("trace"), "writes a .tga file (as tgraph partition -o)");

  m.def(
      "_read_assignment",
      [](const std::string& path, const Trace& trace) {
        return partition::load_assignment(path, trace, path);
      },
      py::arg("path"), py::arg("trace"),
      "Reads a .tga file and checks that it fits `trace` (tgraph.Error if not)");
  m.def("strategies", &partition::strategy_names, "names of the partitioning strategies");
  m.def("_partition", [](const Trace& t, const std::string& method, std::uint32_t k,
                         double imbalance, std::uint64_t seed, const std::string& sticky_base) {
    partition::TracePartition tp;
    {
      py::gil_scoped_release release;
      tp =
          partition::partition_trace(t, method, k, partition_options(imbalance, seed, sticky_base));
    }
    return py::make_tuple(tp.assignment, partition::partition_json(tp, ""));
  });
  m.def("_evaluate", [](const Trace& t, const TraceAssignment& a, const std::string& model,
                        const std::string& calibration) {
    const model::CostModel cm = model::select_cost_model(model, calibration);
    py::gil_scoped_release release;
    return partition::report_json(partition::evaluate(t, a, cm));
  });
}
