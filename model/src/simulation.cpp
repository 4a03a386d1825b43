// SPDX-License-Identifier: MIT
#include "tgraph/model/simulation.hpp"

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tgraph/graph/error.hpp"
#include "tgraph/model/simulator.hpp"

namespace tgraph::model {

std::string to_string(SimulationEngine e) {
  switch (e) {
    case SimulationEngine::builtin:
      return "builtin";
    case SimulationEngine::simgrid:
      return "simgrid";
  }
  return "?";
}

std::string to_string(IntraNodeTransfer t) {
  switch (t) {
    case IntraNodeTransfer::reader:
      return "reader";
    case IntraNodeTransfer::link:
      return "link";
  }
  return "?";
}

bool simgrid_available() {
#ifdef TGRAPH_HAVE_SIMGRID
  return true;
#else
  return false;
#endif
}

namespace {

Prediction builtin_predict(const Trace& trace, const TraceAssignment& a,
                           const SimulatedPlatform& platform) {
  Prediction r;
  r.engine = SimulationEngine::builtin;
  r.k = a.k;
  r.hosts = platform.cluster ? platform.cluster->nodes : 1;
  r.cores = platform.cluster ? platform.cluster->processors() : a.k;
  r.platform = platform.cluster ? std::to_string(platform.cluster->nodes) + "x" +
                                      std::to_string(platform.cluster->cores)
                                : std::string("one machine");
  for (std::size_t s = 0; s < trace.steps.size() && s < a.steps.size(); ++s) {
    std::optional<std::uint64_t> serial;
    if (s < platform.serial_ns.size()) serial = platform.serial_ns[s];
    const Schedule sch = simulate(trace.steps[s], a.steps[s], platform.model, serial);
    r.steps.push_back({sch.makespan_ns, sch.waits, sch.transfer_bytes, 0, 0});
  }
  return r;
}

}  // namespace

Prediction simulate_trace(const Trace& trace, const TraceAssignment& a, SimulationEngine engine,
                          const SimulatedPlatform& platform) {
  if (platform.cluster && platform.cluster->processors() < a.k)
    throw Error("the assignment has " + std::to_string(a.k) + " processors, the cluster " +
                std::to_string(platform.cluster->nodes) + "x" +
                std::to_string(platform.cluster->cores) + " only " +
                std::to_string(platform.cluster->processors()) + " cores");
  const auto t0 = std::chrono::steady_clock::now();
  Prediction r;
  switch (engine) {
    case SimulationEngine::builtin:
      r = builtin_predict(trace, a, platform);
      break;
    case SimulationEngine::simgrid:
      if (platform.file.empty() && !platform.cluster)
        throw OptionError("engine", "simgrid needs {platform} P.xml or {cluster} NxC");
#ifdef TGRAPH_HAVE_SIMGRID
      r = detail::simgrid_predict(trace, a, platform);
#else
      throw OptionError("engine",
                        "simgrid: this tgraph was built without SimGrid (Debian libsimgrid-dev, "
                        "pkg-config simgrid)");
#endif
      break;
  }
  r.intra_node = platform.intra_node;
  bool host = false;
  for (const StepGraph& g : trace.steps) host = host || g.host_ns > 0;
  if (engine == SimulationEngine::builtin) {
    r.model_terms = model_terms(platform.model, !platform.serial_ns.empty(), host);
  } else {
    // SimGrid: the platform's links carry latency and bytes; no parking, no inflation.
    r.model_terms = {"platform_links"};
    if (platform.model.task_overhead_ns > 0) r.model_terms.push_back("task_overhead");
    if (platform.model.mpi_message_overhead_ns > 0) r.model_terms.push_back("message_overhead");
    if (host) r.model_terms.push_back("host_time");
  }
  r.task_overhead_ns = platform.model.task_overhead_ns;
  if (engine == SimulationEngine::simgrid)
    r.message_overhead_ns = platform.model.mpi_message_overhead_ns;
  r.simulation_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  r.makespan_ns = 0;
  for (const StepPrediction& s : r.steps) r.makespan_ns += s.makespan_ns;
  return r;
}

std::string prediction_json(const Prediction& p) {
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t s = 0; s < p.steps.size(); ++s) {
    const StepPrediction& st = p.steps[s];
    steps.push_back({{"step", s},
                     {"makespan_ns", st.makespan_ns},
                     {"messages", st.messages},
                     {"bytes", st.bytes},
                     {"inter_node_messages", st.inter_node_messages},
                     {"inter_node_bytes", st.inter_node_bytes}});
  }
  const nlohmann::json j = {{"engine", to_string(p.engine)},
                            {"platform", p.platform},
                            {"intra_node", to_string(p.intra_node)},
                            {"k", p.k},
                            {"hosts", p.hosts},
                            {"cores", p.cores},
                            {"makespan_ns", p.makespan_ns},
                            {"simulation_ms", p.simulation_ms},
                            {"task_overhead_ns", p.task_overhead_ns},
                            {"message_overhead_ns", p.message_overhead_ns},
                            {"lowered", p.lowered},
                            {"model_terms", p.model_terms},
                            {"per_step", steps}};
  return j.dump();
}

std::string prediction_text(const Prediction& p) {
  char line[256];
  std::snprintf(line, sizeof line,
                "%s on %s (%u hosts, %llu cores), k = %u: predicted makespan %.3f ms over %zu "
                "steps (simulated in %.1f ms)\n",
                to_string(p.engine).c_str(), p.platform.c_str(), p.hosts,
                static_cast<unsigned long long>(p.cores), p.k,
                static_cast<double>(p.makespan_ns) / 1e6, p.steps.size(), p.simulation_ms);
  std::string out = line;
  for (std::size_t s = 0; s < p.steps.size(); ++s) {
    const StepPrediction& st = p.steps[s];
    std::snprintf(line, sizeof line,
                  "  step %zu: %.3f ms, %llu messages, %llu bytes (%llu bytes between nodes)\n", s,
                  static_cast<double>(st.makespan_ns) / 1e6,
                  static_cast<unsigned long long>(st.messages),
                  static_cast<unsigned long long>(st.bytes),
                  static_cast<unsigned long long>(st.inter_node_bytes));
    out += line;
  }
  return out;
}

}  // namespace tgraph::model
