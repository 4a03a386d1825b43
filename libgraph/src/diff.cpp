// SPDX-License-Identifier: MIT
#include "tgraph/graph/diff.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <tuple>
#include <unordered_map>

namespace tgraph {

std::vector<TaskId> match_tasks_by_key(const StepGraph& g, const StepGraph& prev) {
  // The i-th task of g with a key matches the i-th task of prev with that key. Both sides
  // sorted by (key, position) and walked together: no allocation per key, O(n log n).
  auto sorted = [](const StepGraph& s) {
    std::vector<std::pair<StableKey, TaskId>> v(s.tasks.size());
    for (TaskId t = 0; t < s.tasks.size(); ++t) v[t] = {s.tasks[t].key, t};
    std::sort(v.begin(), v.end());
    return v;
  };
  std::vector<TaskId> match(g.tasks.size(), kNoTask);
  if (g.tasks.size() == prev.tasks.size()) {  // fast path: same keys in the same order
    TaskId t = 0;
    while (t < g.tasks.size() && g.tasks[t].key == prev.tasks[t].key) ++t;
    if (t == g.tasks.size()) {
      for (TaskId i = 0; i < t; ++i) match[i] = i;
      return match;
    }
  }
  const auto a = sorted(g), b = sorted(prev);
  std::size_t j = 0;
  for (std::size_t i = 0; i < a.size();) {
    const StableKey key = a[i].first;
    while (j < b.size() && b[j].first < key) ++j;
    for (; i < a.size() && a[i].first == key; ++i)
      if (j < b.size() && b[j].first == key) match[a[i].second] = b[j++].second;
  }
  return match;
}

namespace {

std::string object_name(const StepGraph& g, ObjectId o) {
  return o == kNoObject || o >= g.objects.size() ? std::string() : g.objects[o].name;
}

// "a|b" with the two names in order, so that it does not depend on object ids.
std::string contact_name(const StepGraph& g, const Contact& c) {
  std::string a = object_name(g, c.a), b = object_name(g, c.b);
  if (b < a) std::swap(a, b);
  return a + "|" + b;
}

std::set<std::string> contact_names(const StepGraph& g) {
  std::set<std::string> s;
  for (const Contact& c : g.contacts) s.insert(contact_name(g, c));
  return s;
}

// Objects (by name) whose data task t touches.
std::set<std::string> touched_objects(const StepGraph& g, TaskId t) {
  std::set<std::string> s;
  for (const Access& a : g.accesses_of(t))
    if (g.data[a.datum].object != kNoObject) s.insert(object_name(g, g.data[a.datum].object));
  return s;
}

TaskRef task_ref(const StepGraph& g, TaskId t, const std::vector<std::string>& changed_contacts) {
  TaskRef r;
  r.id = t;
  r.key = g.tasks[t].key;
  r.kind = g.tasks[t].kind < g.kinds.size() ? g.kinds[g.tasks[t].kind] : std::string();
  r.object = object_name(g, g.tasks[t].object);
  const std::set<std::string> touched = touched_objects(g, t);
  for (const std::string& c : changed_contacts) {
    const std::size_t bar = c.find('|');
    if (touched.count(c.substr(0, bar)) != 0 && touched.count(c.substr(bar + 1)) != 0)
      r.caused_by.push_back(c);
  }
  return r;
}

// An edge named by its tasks' (key, occurrence), datum name, kind and whether it is carried.
struct EdgeId {
  StableKey from = 0;
  std::uint32_t from_occ = 0;
  StableKey to = 0;
  std::uint32_t to_occ = 0;
  std::string datum;
  EdgeKind kind = EdgeKind::RAW;
  bool carried = false;
  friend auto operator<=>(const EdgeId&, const EdgeId&) = default;
};

std::set<EdgeId> edge_ids(const StepGraph& g) {
  std::vector<std::uint32_t> occ(g.tasks.size());
  std::unordered_map<StableKey, std::uint32_t> count;
  for (TaskId t = 0; t < g.tasks.size(); ++t) occ[t] = count[g.tasks[t].key]++;
  std::set<EdgeId> s;
  auto add = [&](const Edge& e, bool carried) {
    s.insert({g.tasks[e.from].key, occ[e.from], g.tasks[e.to].key, occ[e.to], g.data[e.datum].name,
              e.kind, carried});
  };
  for (const Edge& e : g.edges) add(e, false);
  for (const Edge& e : g.carried_edges) add(e, true);
  return s;
}

// Group of every object present in `g`, by name (empty groups vector: one group).
std::map<std::string, std::uint32_t> group_of(const StepGraph& g) {
  std::map<std::string, std::uint32_t> m;
  for (ObjectId o = 0; o < g.objects.size(); ++o) {
    if (!g.groups.empty() && o >= g.groups.size()) continue;
    m[g.objects[o].name] = g.groups.empty() ? 0 : g.groups[o];
  }
  return m;
}

// Groups whose members in `from` fall into several groups of `to` (objects of both only);
// members listed in the order of `rank` (the objects' order in a step: bodies first).
std::vector<GroupChange> regrouped(const std::map<std::string, std::uint32_t>& from,
                                   const std::map<std::string, std::uint32_t>& to,
                                   const std::map<std::string, std::size_t>& rank) {
  std::map<std::uint32_t, std::vector<std::string>> members_from, members_to;
  std::map<std::uint32_t, std::set<std::uint32_t>> targets;
  for (const auto& [name, g] : from) {
    auto it = to.find(name);
    if (it == to.end()) continue;
    members_from[g].push_back(name);
    members_to[it->second].push_back(name);
    targets[g].insert(it->second);
  }
  auto by_rank = [&](const std::string& a, const std::string& b) {
    return rank.at(a) < rank.at(b);
  };
  for (auto& [g, m] : members_from) std::sort(m.begin(), m.end(), by_rank);
  for (auto& [g, m] : members_to) std::sort(m.begin(), m.end(), by_rank);
  std::vector<GroupChange> out;
  for (const auto& [g, into] : targets) {
    if (into.size() < 2) continue;
    GroupChange c;
    c.from.push_back(members_from[g]);
    for (std::uint32_t h : into) c.into.push_back(members_to[h]);
    out.push_back(std::move(c));
  }
  return out;
}

// Contacts (by name) between objects of different groups of `groups`.
std::vector<std::string> contacts_across(const std::vector<std::string>& contacts,
                                         const std::vector<std::vector<std::string>>& groups) {
  std::map<std::string, std::size_t> in;
  for (std::size_t i = 0; i < groups.size(); ++i)
    for (const std::string& n : groups[i]) in[n] = i;
  std::vector<std::string> out;
  for (const std::string& c : contacts) {
    const std::size_t bar = c.find('|');
    auto a = in.find(c.substr(0, bar)), b = in.find(c.substr(bar + 1));
    if (a != in.end() && b != in.end() && a->second != b->second) out.push_back(c);
  }
  return out;
}

std::string group_text(const std::vector<std::string>& members) {
  std::string s = "{";
  for (std::size_t i = 0; i < members.size() && i < 3; ++i) s += (i ? ", " : "") + members[i];
  if (members.size() > 3) s += ", +" + std::to_string(members.size() - 3);
  return s + "}";
}

std::string groups_text(const std::vector<std::vector<std::string>>& groups) {
  std::string s;
  for (const auto& g : groups) s += (s.empty() ? "" : " + ") + group_text(g);
  return s;
}

}  // namespace

StepDiff diff_steps(const StepGraph& before, const StepGraph& after) {
  StepDiff d;
  d.same_structure = after.same_structure(before);
  d.loops_before = before.loops.size();
  d.loops_after = after.loops.size();
  const std::set<std::string> ca = contact_names(before), cb = contact_names(after);
  std::set_difference(cb.begin(), cb.end(), ca.begin(), ca.end(),
                      std::back_inserter(d.contacts_added));
  std::set_difference(ca.begin(), ca.end(), cb.begin(), cb.end(),
                      std::back_inserter(d.contacts_removed));
  std::vector<std::string> changed = d.contacts_added;
  changed.insert(changed.end(), d.contacts_removed.begin(), d.contacts_removed.end());

  const std::vector<TaskId> match = match_tasks_by_key(after, before);
  std::vector<bool> kept(before.tasks.size(), false);
  for (TaskId t = 0; t < after.tasks.size(); ++t) {
    if (match[t] == kNoTask) {
      d.tasks_added.push_back(task_ref(after, t, changed));
    } else {
      kept[match[t]] = true;
      ++d.matched_tasks;
    }
  }
  for (TaskId t = 0; t < before.tasks.size(); ++t)
    if (!kept[t]) d.tasks_removed.push_back(task_ref(before, t, changed));

  const std::set<EdgeId> ea = edge_ids(before), eb = edge_ids(after);
  auto ref = [](const EdgeId& e) { return EdgeRef{e.from, e.to, e.datum, e.kind, e.carried}; };
  for (const EdgeId& e : eb)
    if (ea.count(e) == 0) d.edges_added.push_back(ref(e));
  for (const EdgeId& e : ea)
    if (eb.count(e) == 0) d.edges_removed.push_back(ref(e));

  const auto ga = group_of(before), gb = group_of(after);
  std::map<std::string, std::size_t> rank;
  for (ObjectId o = 0; o < after.objects.size(); ++o) rank.emplace(after.objects[o].name, o);
  for (ObjectId o = 0; o < before.objects.size(); ++o)
    rank.emplace(before.objects[o].name, after.objects.size() + o);
  d.groups_split = regrouped(ga, gb, rank);
  for (GroupChange& c : d.groups_split) c.contacts = contacts_across(d.contacts_removed, c.into);
  // A merge is a split seen backwards.
  for (GroupChange& c : regrouped(gb, ga, rank)) {
    std::swap(c.from, c.into);
    c.contacts = contacts_across(d.contacts_added, c.from);
    d.groups_merged.push_back(std::move(c));
  }
  return d;
}

void add_processor_changes(StepDiff& d, const StepGraph& before, const Assignment& a_before,
                           const StepGraph& after, const Assignment& a_after) {
  d.processor_changes.clear();
  const std::vector<TaskId> match = match_tasks_by_key(after, before);
  for (TaskId t = 0; t < after.tasks.size() && t < a_after.proc.size(); ++t) {
    if (match[t] == kNoTask || match[t] >= a_before.proc.size()) continue;
    const ProcId from = a_before.proc[match[t]], to = a_after.proc[t];
    if (from != to) d.processor_changes.push_back({task_ref(after, t, {}), from, to});
  }
}

std::string step_diff_summary(const StepDiff& d) {
  const bool any = !d.same_structure || !d.tasks_added.empty() || !d.tasks_removed.empty() ||
                   !d.contacts_added.empty() || !d.contacts_removed.empty();
  std::string s;
  if (!any) {
    s = "no structural change";
  } else {
    s = "+" + std::to_string(d.tasks_added.size()) + "/-" + std::to_string(d.tasks_removed.size()) +
        " tasks, +" + std::to_string(d.edges_added.size()) + "/-" +
        std::to_string(d.edges_removed.size()) + " edges";
    if (!d.contacts_added.empty() || !d.contacts_removed.empty()) {
      s += ", contacts";
      for (const std::string& c : d.contacts_added) s += " +" + c;
      for (const std::string& c : d.contacts_removed) s += " -" + c;
    }
    for (const GroupChange& c : d.groups_merged) s += ", groups merged: " + groups_text(c.from);
    for (const GroupChange& c : d.groups_split)
      s += ", group split: " + groups_text(c.from) + " -> " + groups_text(c.into);
    if (d.loops_before != d.loops_after)
      s += ", loops " + std::to_string(d.loops_before) + " -> " + std::to_string(d.loops_after);
  }
  if (!d.processor_changes.empty())
    s += "; " + std::to_string(d.processor_changes.size()) + " tasks changed processor";
  return s;
}

namespace {

using nlohmann::json;

json task_json(const TaskRef& t) {
  return {{"id", t.id},
          {"key", t.key},
          {"kind", t.kind},
          {"object", t.object},
          {"caused_by", t.caused_by}};
}

json edge_json(const EdgeRef& e) {
  return {{"from_key", e.from},
          {"to_key", e.to},
          {"datum", e.datum},
          {"kind", to_string(e.kind)},
          {"carried", e.carried}};
}

json group_json(const GroupChange& c) {
  return {{"from", c.from}, {"into", c.into}, {"contacts", c.contacts}};
}

}  // namespace

std::string step_diff_json(const StepDiff& d, std::size_t a, std::size_t b) {
  json added = json::array(), removed = json::array(), eadded = json::array(),
       eremoved = json::array(), merged = json::array(), split = json::array(),
       moved = json::array();
  for (const TaskRef& t : d.tasks_added) added.push_back(task_json(t));
  for (const TaskRef& t : d.tasks_removed) removed.push_back(task_json(t));
  for (const EdgeRef& e : d.edges_added) eadded.push_back(edge_json(e));
  for (const EdgeRef& e : d.edges_removed) eremoved.push_back(edge_json(e));
  for (const GroupChange& c : d.groups_merged) merged.push_back(group_json(c));
  for (const GroupChange& c : d.groups_split) split.push_back(group_json(c));
  for (const ProcessorChange& c : d.processor_changes) {
    json j = task_json(c.task);
    j.erase("caused_by");
    j["from"] = c.from;
    j["to"] = c.to;
    moved.push_back(j);
  }
  const json j = {{"steps", {a, b}},
                  {"same_structure", d.same_structure},
                  {"summary", step_diff_summary(d)},
                  {"matched_tasks", d.matched_tasks},
                  {"tasks_added", added},
                  {"tasks_removed", removed},
                  {"edges_added", eadded},
                  {"edges_removed", eremoved},
                  {"contacts_added", d.contacts_added},
                  {"contacts_removed", d.contacts_removed},
                  {"groups_merged", merged},
                  {"groups_split", split},
                  {"loops", {{"before", d.loops_before}, {"after", d.loops_after}}},
                  {"processor_changes", moved}};
  return j.dump();
}

std::string step_diff_text(const StepDiff& d, std::size_t a, std::size_t b) {
  std::string s = "steps " + std::to_string(a) + " -> " + std::to_string(b) + ": " +
                  step_diff_summary(d) + "\n";
  auto task_line = [](char sign, const TaskRef& t) {
    std::string l = std::string("  ") + sign + " task " + t.kind +
                    (t.object.empty() ? "" : " on " + t.object) + " (key " + std::to_string(t.key) +
                    ")";
    if (!t.caused_by.empty()) {
      l += ", contact";
      for (const std::string& c : t.caused_by) l += " " + c;
    }
    return l + "\n";
  };
  for (const TaskRef& t : d.tasks_added) s += task_line('+', t);
  for (const TaskRef& t : d.tasks_removed) s += task_line('-', t);
  for (const std::string& c : d.contacts_added) s += "  + contact " + c + "\n";
  for (const std::string& c : d.contacts_removed) s += "  - contact " + c + "\n";
  for (const GroupChange& c : d.groups_merged) {
    s += "  groups merged: " + groups_text(c.from) + " -> " + groups_text(c.into);
    for (const std::string& k : c.contacts)
      s += (&k == &c.contacts.front() ? " by contact " : ", ") + k;
    s += "\n";
  }
  for (const GroupChange& c : d.groups_split) {
    s += "  group split: " + groups_text(c.from) + " -> " + groups_text(c.into);
    for (const std::string& k : c.contacts)
      s += (&k == &c.contacts.front() ? " by losing contact " : ", ") + k;
    s += "\n";
  }
  for (const ProcessorChange& c : d.processor_changes)
    s += "  task " + c.task.kind + (c.task.object.empty() ? "" : " on " + c.task.object) +
         " (key " + std::to_string(c.task.key) + "): processor " + std::to_string(c.from) + " -> " +
         std::to_string(c.to) + "\n";
  return s;
}

StepDiff diff_trace_steps(const Trace& trace, const std::string& trace_name, std::size_t a,
                          std::size_t b, const TraceAssignment* assignment) {
  const StepGraph& ga = step_at(trace, a, trace_name, "steps");
  const StepGraph& gb = step_at(trace, b, trace_name, "steps");
  StepDiff d = diff_steps(ga, gb);
  if (assignment) add_processor_changes(d, ga, assignment->steps[a], gb, assignment->steps[b]);
  return d;
}

}  // namespace tgraph
