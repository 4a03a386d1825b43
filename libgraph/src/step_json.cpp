// SPDX-License-Identifier: MIT
#include "tgraph/graph/step_json.hpp"

#include <nlohmann/json.hpp>

namespace tgraph {

namespace {

using nlohmann::json;

json edges_json(const StepGraph& g, const std::vector<Edge>& edges) {
  json a = json::array();
  for (const Edge& e : edges)
    a.push_back({{"from", e.from},
                 {"to", e.to},
                 {"datum", e.datum},
                 {"kind", to_string(e.kind)},
                 {"bytes", g.data[e.datum].bytes}});
  return a;
}

}  // namespace

std::string step_graph_json(const StepGraph& g, std::size_t step) {
  json tasks = json::array();
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const Task& task = g.tasks[t];
    json acc = json::array();
    for (const Access& a : g.accesses_of(t))
      acc.push_back({{"datum", a.datum}, {"mode", to_string(a.mode)}});
    tasks.push_back({{"id", t},
                     {"kind", g.kinds[task.kind]},
                     {"object", task.object == kNoObject ? json(nullptr) : json(task.object)},
                     {"cost_ns", task.cost_ns},
                     {"loop", task.loop == kNoLoop ? json(nullptr) : json(task.loop)},
                     {"key", task.key},
                     {"accesses", acc}});
  }
  json data = json::array();
  for (const Datum& d : g.data)
    data.push_back({{"name", d.name},
                    {"object", d.object == kNoObject ? json(nullptr) : json(d.object)},
                    {"bytes", d.bytes}});
  json objects = json::array();
  for (const ObjectInfo& o : g.objects) objects.push_back(o.name);
  json loops = json::array();
  for (const Loop& l : g.loops)
    loops.push_back({{"condition", l.condition},
                     {"first", l.first},
                     {"last", l.last},
                     {"iterations", l.iterations},
                     {"max_iterations", l.max_iterations}});
  json contacts = json::array();
  for (const Contact& c : g.contacts) contacts.push_back({c.a, c.b});
  const json j = {{"step", step},
                  {"objects", objects},
                  {"data", data},
                  {"tasks", tasks},
                  {"loops", loops},
                  {"edges", edges_json(g, g.edges)},
                  {"carried_edges", edges_json(g, g.carried_edges)},
                  {"contacts", contacts},
                  {"groups", g.groups}};
  return j.dump(1) + "\n";
}

}  // namespace tgraph
