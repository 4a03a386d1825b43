// SPDX-License-Identifier: MIT
// The partition executor's stall report (partition_report.hpp).
#include "partition_report.hpp"

namespace tgraph::replay::detail {

std::string stall_report(const ExecGraph& x, const PartitionPlan& plan,
                         const std::vector<ThreadStand>& threads) {
  const auto label = [&x](TaskId t) {
    return t < x.graph.tasks.size()
               ? "task " + std::to_string(t) + " (" + x.graph.kind_name(t) + ")"
               : std::string("no task");
  };
  std::string out;
  for (std::uint32_t p = 0; p < threads.size(); ++p) {
    const auto [kind, id, task, inside, inside_of] = threads[p];
    if (!out.empty()) out += "; ";
    out += "thread " + std::to_string(p);
    if (inside < x.graph.tasks.size()) {
      out += " runs " + label(inside) + ", " +
             (inside_of == p ? std::string("ahead in its own program")
                             : "taken from thread " + std::to_string(inside_of) + "'s program") +
             ", inside its wait:";
      if (kind == 0) continue;
      out += " it";
    }
    if (kind == 1 && id < x.graph.tasks.size()) {
      out += " waits for " + label(id) + " on thread " + std::to_string(x.assignment.proc[id]);
      for (const Edge& e : x.graph.edges)
        if (e.from == id && e.to == task && e.datum < x.graph.data.size()) {
          out += " (datum '" + x.graph.data[e.datum].name + "')";
          break;
        }
      if (task < x.graph.tasks.size()) out += " before running " + label(task);
    } else if (kind == 2) {
      out += " waits for the decision of loop " + std::to_string(id);
    } else if (kind == 3) {
      out += " waits at the first-touch barrier";
    } else if (kind == 4 && id < plan.combines.size()) {
      const Combine& c = plan.combines[id];
      out += " waits for " + label(plan.procs[c.home].ops[c.head].task) +
             " and the tasks after it, run by the last of their " + std::to_string(c.parties) +
             " threads to arrive";
    } else if (kind == 5) {
      out += " has finished its program and waits for the other threads to finish theirs";
    } else if (kind == 6 && id < x.graph.tasks.size()) {
      out += " waits for " + label(id) + ", taken from its program by another thread";
    } else if (task < x.graph.tasks.size()) {
      out += " runs or last ran " + label(task);
    } else {
      out += " has run no task yet";
    }
  }
  return out;
}

}  // namespace tgraph::replay::detail
