// SPDX-License-Identifier: MIT
// `tgraph-mpi replay`'s JSON and text reports.
#include <nlohmann/json.hpp>
#include <sstream>

#include "tgraph/mpi/replay.hpp"

namespace tgraph::mpi {
namespace {

nlohmann::json pairs(const Traffic& measured, const Traffic& predicted, bool messages_counted) {
  nlohmann::json out = nlohmann::json::array();
  for (std::uint32_t f = 0; f < measured.ranks; ++f)
    for (std::uint32_t t = 0; t < measured.ranks; ++t) {
      const std::size_t i = f * measured.ranks + t;
      if (f == t) continue;
      if (measured.messages[i] + predicted.messages[i] + measured.decisions[i] +
              predicted.decisions[i] + measured.bytes[i] ==
          0)
        continue;
      nlohmann::json p = {{"from", f},
                     {"to", t},
                     {"messages", measured.messages[i]},
                     {"bytes", measured.bytes[i]},
                     {"decisions", measured.decisions[i]},
                     {"predicted_messages", predicted.messages[i]},
                     {"predicted_bytes", predicted.bytes[i]},
                     {"predicted_decisions", predicted.decisions[i]}};
      if (!messages_counted) p["messages"] = p["decisions"] = nullptr;
      out.push_back(std::move(p));
    }
  return out;
}

double ratio(std::int64_t a, std::int64_t b) {
  return b > 0 ? static_cast<double>(a) / static_cast<double>(b) : 0.0;
}

nlohmann::json common(const MpiStepResult& s, bool messages_counted) {
  nlohmann::json j = {{"wall_ns", s.wall_ns},
          {"messages", s.measured.total_messages()},
          {"bytes", s.measured.total_bytes()},
          {"predicted_messages", s.predicted.total_messages()},
          {"predicted_bytes", s.predicted.total_bytes()},
          {"decision_messages", s.measured.total_decisions()},
          {"predicted_decision_messages", s.predicted.total_decisions()},
          {"bytes_match", s.measured == s.predicted},
          {"entering_bytes", s.measured.entering_bytes},
          {"migrated_bytes", s.migrated_bytes},
          {"local_wait_ns", s.local_wait_ns},
          {"message_wait_ns", s.message_wait_ns},
          {"decision_wait_ns", s.decision_wait_ns},
          {"received", s.received},
          {"overlap",
           s.received > 0 ? static_cast<double>(s.hidden) / static_cast<double>(s.received) : 1.0},
          {"decision_latency_ns",
           s.decisions_received > 0
               ? s.decision_latency_ns / static_cast<std::int64_t>(s.decisions_received)
               : 0}};
  if (!messages_counted) {
    // StarPU-MPI counts bytes per destination only: no messages, decisions or waits here.
    for (const char* key : {"messages", "decision_messages", "bytes_match", "entering_bytes",
                            "local_wait_ns", "message_wait_ns", "decision_wait_ns", "received",
                            "overlap", "decision_latency_ns"})
      j[key] = nullptr;
  }
  return j;
}

MpiStepResult total(const MpiReplayResult& r) {
  MpiStepResult t;
  t.measured = Traffic(r.ranks);
  t.predicted = Traffic(r.ranks);
  for (const MpiStepResult& s : r.steps) {
    t.wall_ns += s.wall_ns;
    t.measured.add(s.measured);
    t.predicted.add(s.predicted);
    t.local_wait_ns += s.local_wait_ns;
    t.message_wait_ns += s.message_wait_ns;
    t.decision_wait_ns += s.decision_wait_ns;
    t.received += s.received;
    t.hidden += s.hidden;
    t.decisions_received += s.decisions_received;
    t.decision_latency_ns += s.decision_latency_ns;
    t.migrated_bytes += s.migrated_bytes;
    t.sequential_ns += s.sequential_ns;
  }
  return t;
}

}  // namespace

std::string to_json(const MpiReplayResult& r, const std::string& trace_name) {
  const MpiStepResult t = total(r);
  nlohmann::json j = common(t, r.messages_counted());
  j["trace"] = trace_name;
  j["policy"] = r.policy == MpiPolicy::kStarpuMpi ? "starpu-mpi" : "partition";
  j["ranks"] = r.ranks;
  j["threads_per_rank"] = r.threads_per_rank;
  j["check"] =
      r.identical ? nlohmann::json(*r.identical ? "identical" : "differs") : nlohmann::json();
  j["checksum"] = r.checksum;
  j["sequential_ns"] = r.sequential_ns;
  j["speedup"] = ratio(r.sequential_ns, r.wall_ns);
  j["per_pair"] = pairs(t.measured, t.predicted, r.messages_counted());
  nlohmann::json steps = nlohmann::json::array();
  for (const MpiStepResult& s : r.steps) {
    nlohmann::json js = common(s, r.messages_counted());
    js["sequential_ns"] = s.sequential_ns;
    js["speedup"] = ratio(s.sequential_ns, s.wall_ns);
    js["repartitioned"] = s.repartitioned;
    steps.push_back(std::move(js));
  }
  j["per_step"] = std::move(steps);
  return j.dump();
}

std::string to_text(const MpiReplayResult& r, const std::string& trace_name) {
  const MpiStepResult t = total(r);
  std::ostringstream o;
  o << trace_name << ": " << r.steps.size() << " steps on " << r.ranks << " ranks x "
    << r.threads_per_rank << " threads" << (r.messages_counted() ? "" : " (StarPU-MPI)")
    << "\n";
  o << "  wall " << static_cast<double>(t.wall_ns) / 1e6 << " ms, sequential "
    << static_cast<double>(r.sequential_ns) / 1e6 << " ms, speed-up "
    << ratio(r.sequential_ns, r.wall_ns) << "\n";
  if (!r.messages_counted()) {
    o << "  bytes " << t.measured.total_bytes() << " (tgraph's schedule: "
      << t.predicted.total_bytes() << " in " << t.predicted.total_messages()
      << " messages); migrated " << t.migrated_bytes << " bytes\n";
    if (r.identical) o << "  check: " << (*r.identical ? "identical" : "differs") << "\n";
    return o.str();
  }
  o << "  messages " << t.measured.total_messages() << " (predicted "
    << t.predicted.total_messages() << "), bytes " << t.measured.total_bytes() << " (predicted "
    << t.predicted.total_bytes() << "), loop decisions " << t.measured.total_decisions()
    << ", per rank pair " << (t.measured == t.predicted ? "as predicted" : "NOT as predicted")
    << "\n";
  o << "  blocked: local " << static_cast<double>(t.local_wait_ns) / 1e6 << " ms, messages "
    << static_cast<double>(t.message_wait_ns) / 1e6 << " ms, decisions "
    << static_cast<double>(t.decision_wait_ns) / 1e6 << " ms; migrated " << t.migrated_bytes
    << " bytes\n";
  if (r.identical) o << "  check: " << (*r.identical ? "identical" : "differs") << "\n";
  return o.str();
}

}  // namespace tgraph::mpi
