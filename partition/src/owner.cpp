// SPDX-License-Identifier: MIT
// `owner`: the owner-compute rule (paper section 3.2).
#include <algorithm>
#include <numeric>
#include <string_view>
#include <unordered_map>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

constexpr ObjectId kUnowned = kNoObject;

// The object a task belongs to for placement: the object whose data it writes the most
// bytes of (ties: lowest id); else the one whose data it reads most; else its own object;
// else none (tasks on shared data only, such as solver scalars).
ObjectId owner_of(const StepGraph& g, TaskId t) {
  std::unordered_map<ObjectId, std::uint64_t> written, read;
  for (const Access& acc : g.accesses_of(t)) {
    const Datum& d = g.data[acc.datum];
    if (d.object == kNoObject) continue;
    (writes(acc.mode) ? written : read)[d.object] += std::max<std::uint64_t>(d.bytes, 1);
  }
  auto best = [](const std::unordered_map<ObjectId, std::uint64_t>& m) {
    ObjectId o = kUnowned;
    std::uint64_t w = 0;
    for (const auto& [obj, bytes] : m)
      if (bytes > w || (bytes == w && obj < o)) {
        o = obj;
        w = bytes;
      }
    return o;
  };
  if (!written.empty()) return best(written);
  if (!read.empty()) return best(read);
  return g.tasks[t].object;
}

// Improves a placement: moves one object off the most loaded processor, or swaps one of its
// objects with a lighter one elsewhere, whichever lowers the pair's maximum most; stops when
// the maximum is within `limit` or nothing lowers it.
void refine(const std::vector<std::pair<ObjectId, std::uint64_t>>& objs, std::vector<ProcId>& where,
            std::vector<std::uint64_t>& load, double limit) {
  const auto k = static_cast<ProcId>(load.size());
  for (std::size_t round = 0; round < 4 * objs.size() + 16; ++round) {
    const auto p = static_cast<ProcId>(std::max_element(load.begin(), load.end()) - load.begin());
    if (static_cast<double>(load[p]) <= limit) return;
    std::uint64_t best_peak = load[p];
    std::size_t best_a = SIZE_MAX, best_b = SIZE_MAX;
    ProcId best_q = p;
    for (std::size_t a = 0; a < objs.size(); ++a) {
      if (where[a] != p) continue;
      const std::uint64_t wa = objs[a].second;
      for (ProcId q = 0; q < k; ++q) {
        if (q == p) continue;
        const std::uint64_t peak = std::max(load[p] - wa, load[q] + wa);
        if (peak < best_peak) {
          best_peak = peak;
          best_a = a;
          best_b = SIZE_MAX;
          best_q = q;
        }
      }
      for (std::size_t b = 0; b < objs.size(); ++b) {
        const std::uint64_t wb = objs[b].second;
        if (where[b] == p || wb >= wa) continue;
        const ProcId q = where[b];
        const std::uint64_t peak = std::max(load[p] - wa + wb, load[q] + wa - wb);
        if (peak < best_peak) {
          best_peak = peak;
          best_a = a;
          best_b = b;
          best_q = q;
        }
      }
    }
    if (best_a == SIZE_MAX) return;
    load[p] -= objs[best_a].second;
    load[best_q] += objs[best_a].second;
    where[best_a] = best_q;
    if (best_b != SIZE_MAX) {
      load[best_q] -= objs[best_b].second;
      load[p] += objs[best_b].second;
      where[best_b] = p;
    }
  }
}

// Processor of each object (by name) in a previous assignment: where most of its work ran.
std::unordered_map<std::string_view, ProcId> object_processors(const StepGraph& g, const Assignment& a) {
  std::unordered_map<ObjectId, std::unordered_map<ProcId, std::uint64_t>> work;
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const ObjectId o = owner_of(g, t);
    if (o != kUnowned && o < g.objects.size()) work[o][a.proc[t]] += g.tasks[t].cost_ns * g.runs(t) + 1;
  }
  std::unordered_map<std::string_view, ProcId> out;
  for (const auto& [o, per] : work) {
    ProcId best = 0;
    std::uint64_t w = 0;
    for (const auto& [p, x] : per)
      if (x > w || (x == w && p < best)) {
        best = p;
        w = x;
      }
    out[g.objects[o].name] = best;
  }
  return out;
}

/// Objects (with the tasks that work on them) spread over K processors by measured cost:
/// longest processing time first, then moves and swaps that lower the maximum load. Given
/// the previous step, objects stay where they were unless the tolerance is exceeded.
class Owner final : public Strategy {
 public:
  std::string_view name() const override { return "owner"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                      const Options& options) override {
    const auto n = static_cast<TaskId>(g.tasks.size());
    const std::vector<std::uint64_t> work = task_work(g);
    std::vector<ObjectId> owner(n);
    std::unordered_map<ObjectId, std::uint64_t> object_work;
    for (TaskId t = 0; t < n; ++t) {
      owner[t] = owner_of(g, t);
      if (owner[t] != kUnowned) object_work[owner[t]] += work[t];
    }
    // No task works on an object's data: owner-compute has nothing to go by and would put
    // every task on the processor of the first one. List scheduling places such a graph by
    // its critical path instead, on every processor its parallelism can use.
    if (object_work.empty() && k > 1 && n > 0) {
      Result r = make_list()->partition(g, k, Previous{}, options);
      r.stats.placed_by = "list";
      r.stats.warnings.clear();  // partition() adds the empty-processor check for owner
      r.stats.warnings.push_back(
          "owner: the tasks have no objects (kNoObject), so owner-compute has nothing to "
          "place by; placed by list scheduling (list) instead");
      return r;
    }

    // Longest processing time first: heaviest object to the least loaded processor.
    std::vector<std::pair<ObjectId, std::uint64_t>> objs(object_work.begin(), object_work.end());
    std::sort(objs.begin(), objs.end(), [](const auto& a, const auto& b) {
      return a.second != b.second ? a.second > b.second : a.first < b.first;
    });
    std::vector<std::uint64_t> load(k, 0);
    auto least_loaded = [&] {
      return static_cast<ProcId>(std::min_element(load.begin(), load.end()) - load.begin());
    };
    // Objects keep the processor they had in the previous step (matched by name), so that
    // an unchanged scene does not migrate; the others go by LPT.
    std::unordered_map<std::string_view, ProcId> before;
    if (prev.graph != nullptr && prev.assignment->k == k) before = object_processors(*prev.graph, *prev.assignment);
    std::vector<ProcId> where(objs.size(), k);
    for (std::size_t i = 0; i < objs.size(); ++i) {
      if (objs[i].first >= g.objects.size()) continue;
      auto it = before.find(g.objects[objs[i].first].name);
      if (it == before.end()) continue;
      where[i] = it->second;
      load[where[i]] += objs[i].second;
    }
    for (std::size_t i = 0; i < objs.size(); ++i)
      if (where[i] == k) {
        where[i] = least_loaded();
        load[where[i]] += objs[i].second;
      }
    std::uint64_t total = 0;
    for (std::uint64_t l : load) total += l;
    // From scratch: as balanced as moves and swaps get; with a previous placement: only
    // until the imbalance tolerance is met, so that few objects move.
    const double limit = before.empty() ? 0.0 : static_cast<double>(total) / k * options.imbalance;
    refine(objs, where, load, limit);
    std::unordered_map<ObjectId, ProcId> proc_of_object;
    for (std::size_t i = 0; i < objs.size(); ++i) proc_of_object[objs[i].first] = where[i];

    Result r;
    r.assignment.k = k;
    r.assignment.proc.assign(n, 0);
    // Owned tasks go with their object; tasks on shared data only go where most bytes of
    // their data are (ties and no affinity: the least loaded processor).
    std::vector<bool> placed(n, false);
    for (TaskId t = 0; t < n; ++t)
      if (owner[t] != kUnowned) {
        r.assignment.proc[t] = proc_of_object[owner[t]];
        placed[t] = true;
      }
    place_by_affinity(g, work, k, placed, r.assignment.proc, load);
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_owner() { return std::make_unique<Owner>(); }

}  // namespace tgraph::partition::detail
