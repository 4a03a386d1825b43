// SPDX-License-Identifier: MIT
// Trace and assignment helpers.
#include "tgraph/graph/trace.hpp"

#include <fstream>
#include <numeric>
#include <thread>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph {

std::string machine_description() {
  std::string model;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      if (auto colon = line.find(':'); colon != std::string::npos) model = line.substr(colon + 2);
      break;
    }
  }
  if (model.empty()) model = "unknown cpu";
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

const StepGraph& step_at(const Trace& trace, std::size_t step, const std::string& trace_name,
                         const std::string& field) {
  if (step >= trace.steps.size())
    throw OptionError(field, "trace " + trace_name + " has " + std::to_string(trace.steps.size()) +
                                 " steps, no step " + std::to_string(step));
  return trace.steps[step];
}

bool contacts_changed(const Trace& trace, std::size_t i) {
  if (i == 0 || i >= trace.steps.size()) return false;
  const StepGraph& a = trace.steps[i - 1];
  const StepGraph& b = trace.steps[i];
  if (a.contacts.size() != b.contacts.size()) return true;
  // Compare by object names: ids may differ between steps.
  for (std::size_t c = 0; c < a.contacts.size(); ++c) {
    const auto& ca = a.contacts[c];
    const auto& cb = b.contacts[c];
    if (a.objects[ca.a].name != b.objects[cb.a].name || a.objects[ca.b].name != b.objects[cb.b].name)
      return true;
  }
  return false;
}

std::vector<TaskId> tasks_of(const Assignment& a, ProcId p) {
  if (!a.order.empty()) return p < a.order.size() ? a.order[p] : std::vector<TaskId>{};
  std::vector<TaskId> out;
  for (TaskId t = 0; t < a.proc.size(); ++t)
    if (a.proc[t] == p) out.push_back(t);
  return out;
}

}  // namespace tgraph
