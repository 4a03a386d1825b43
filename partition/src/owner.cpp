// SPDX-License-Identifier: MIT
// `owner`: the owner-compute rule (paper section 3.2).
#include <algorithm>
#include <numeric>
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

// Improves an LPT placement: moves one object off the most loaded processor, or swaps one of
// its objects with a lighter one elsewhere, whichever lowers the pair's maximum most; stops
// when nothing lowers the maximum.
void refine(const std::vector<std::pair<ObjectId, std::uint64_t>>& objs, std::vector<ProcId>& where,
            std::vector<std::uint64_t>& load) {
  const auto k = static_cast<ProcId>(load.size());
  for (std::size_t round = 0; round < 4 * objs.size() + 16; ++round) {
    const auto p = static_cast<ProcId>(std::max_element(load.begin(), load.end()) - load.begin());
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

/// Objects (with the tasks that work on them) spread over K processors by measured cost:
/// longest processing time first, then moves and swaps that lower the maximum load.
class Owner final : public Strategy {
 public:
  std::string_view name() const override { return "owner"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&, const Options&) override {
    const auto n = static_cast<TaskId>(g.tasks.size());
    const std::vector<std::uint64_t> work = task_work(g);
    std::vector<ObjectId> owner(n);
    std::unordered_map<ObjectId, std::uint64_t> object_work;
    for (TaskId t = 0; t < n; ++t) {
      owner[t] = owner_of(g, t);
      if (owner[t] != kUnowned) object_work[owner[t]] += work[t];
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
    std::vector<ProcId> where(objs.size());
    for (std::size_t i = 0; i < objs.size(); ++i) {
      where[i] = least_loaded();
      load[where[i]] += objs[i].second;
    }
    refine(objs, where, load);
    std::unordered_map<ObjectId, ProcId> proc_of_object;
    for (std::size_t i = 0; i < objs.size(); ++i) proc_of_object[objs[i].first] = where[i];

    Result r;
    r.assignment.k = k;
    r.assignment.proc.assign(n, 0);
    // Which processors hold each datum (bytes of affinity), from the owned tasks.
    std::vector<std::vector<ProcId>> holders(g.data.size());
    auto hold = [&](TaskId t, ProcId p) {
      for (const Access& acc : g.accesses_of(t)) {
        auto& h = holders[acc.datum];
        if (std::find(h.begin(), h.end(), p) == h.end()) h.push_back(p);
      }
    };
    for (TaskId t = 0; t < n; ++t)
      if (owner[t] != kUnowned) {
        r.assignment.proc[t] = proc_of_object[owner[t]];
        hold(t, r.assignment.proc[t]);
      }
    // Tasks on shared data only: the processor holding most bytes of their data; ties and
    // no affinity go to the least loaded one.
    std::vector<std::uint64_t> score(k);
    for (TaskId t = 0; t < n; ++t) {
      if (owner[t] != kUnowned) continue;
      std::fill(score.begin(), score.end(), 0);
      for (const Access& acc : g.accesses_of(t))
        for (ProcId p : holders[acc.datum]) score[p] += std::max<std::uint64_t>(g.data[acc.datum].bytes, 1);
      ProcId best = least_loaded();
      for (ProcId p = 0; p < k; ++p)
        if (score[p] > score[best] || (score[p] == score[best] && load[p] < load[best])) best = p;
      r.assignment.proc[t] = best;
      load[best] += work[t];
      hold(t, best);
    }
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_owner() { return std::make_unique<Owner>(); }

}  // namespace tgraph::partition::detail
