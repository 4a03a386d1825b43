// SPDX-License-Identifier: MIT
#include "recording.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <unordered_map>

namespace tgraph::ode::detail {

StepGraph build_step_graph(const StepLog& log) {
  StepGraph g;
  g.host_ns = static_cast<std::uint64_t>(std::max<std::int64_t>(log.host_ns, 0));
  std::unordered_map<std::uint32_t, const CallRecord*> calls;
  std::vector<const SegmentRecord*> order;
  std::unordered_map<const SegmentRecord*, const AccessRecord*> access_base;
  for (const SlotLog& part : log.slots) {
    for (const CallRecord& c : part.calls) calls.emplace(c.id, &c);
    for (const SegmentRecord& s : part.segments) access_base.emplace(&s, part.accesses.data());
  }
  for (const SlotLog& part : log.slots)
    for (const SegmentRecord& s : part.segments)
      if (calls.count(s.call)) order.push_back(&s);
  std::sort(order.begin(), order.end(), [](const SegmentRecord* a, const SegmentRecord* b) {
    return a->seq != b->seq ? a->seq < b->seq : a->call < b->call;
  });
  // The order numbers are topological but depend on which thread ran what. A canonical order
  // instead: by depth (one more than the deepest part it follows), then stable key, so that
  // the same relations give the same program order (and the same structure) in every step.
  {
    std::unordered_map<std::uint64_t, std::uint32_t> depth;  // (call << 32 | seg)
    std::unordered_map<std::uint32_t, std::uint32_t> released_after;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> signalled_after;
    std::unordered_map<const SegmentRecord*, std::pair<std::uint32_t, StableKey>> rank;
    for (const SegmentRecord* s : order) {  // order numbers: predecessors first
      const CallRecord& c = *calls.at(s->call);
      std::uint32_t d = 0;
      if (s->seg > 0) {
        d = depth.at((std::uint64_t{s->call} << 32) | (s->seg - 1)) + 1;
      } else {
        if (c.poster_call != CallRecord::kNone) {
          auto it = depth.find((std::uint64_t{c.poster_call} << 32) | c.poster_seg);
          if (it != depth.end()) d = std::max(d, it->second + 1);
        }
        if (auto it = released_after.find(c.id); it != released_after.end())
          d = std::max(d, it->second + 1);
      }
      const AccessRecord* acc = access_base.at(s) + s->access_begin;
      for (std::uint32_t i = 0; i < s->access_count; ++i)
        if (acc[i].kind == AccessRecord::kWaitRead)
          if (auto it = signalled_after.find({acc[i].a, acc[i].b}); it != signalled_after.end())
            d = std::max(d, it->second + 1);
      depth[(std::uint64_t{s->call} << 32) | s->seg] = d;
      for (std::uint32_t i = 0; i < s->access_count; ++i) {
        if (acc[i].kind == AccessRecord::kRelease) {
          std::uint32_t& r = released_after[acc[i].a];
          r = std::max(r, d);
        } else if (acc[i].kind == AccessRecord::kSignal) {
          std::uint32_t& r = signalled_after[{acc[i].a, acc[i].b}];
          r = std::max(r, d);
        }
      }
      rank[s] = {d, segment_key(c.key, s->seg)};
    }
    std::stable_sort(
        order.begin(), order.end(),
        [&](const SegmentRecord* a, const SegmentRecord* b) { return rank.at(a) < rank.at(b); });
  }

  auto label = [&](const CallRecord& c) {
    char key[20];
    std::snprintf(key, sizeof key, "%016llx", static_cast<unsigned long long>(c.key));
    return std::string(c.name) + " [" + std::to_string(c.instance) + "] " + key;
  };
  // Data by relation: (kind, a, b) -> id.
  std::map<std::tuple<std::uint32_t, std::uint64_t, std::uint64_t>, DatumId> data;
  auto datum = [&](std::uint32_t kind, std::uint64_t a, std::uint64_t b, auto&& name) -> DatumId {
    auto [it, fresh] = data.emplace(std::tuple{kind, a, b}, static_cast<DatumId>(g.data.size()));
    if (fresh) g.data.push_back(Datum{name(), kNoObject, 0});
    return it->second;
  };
  // Which calls are released by someone in this log, which waits are signalled.
  std::unordered_map<std::uint32_t, bool> released;
  std::unordered_map<std::uint64_t, bool> signalled;
  for (const SlotLog& part : log.slots)
    for (const AccessRecord& a : part.accesses) {
      if (a.kind == AccessRecord::kRelease) released[a.a] = true;
      if (a.kind == AccessRecord::kSignal) signalled[(std::uint64_t{a.a} << 32) | a.b] = true;
    }
  // A wait's uses this step, numbered from 0 (its generation counts from its allocation).
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> use;
  for (const SlotLog& part : log.slots)
    for (const AccessRecord& a : part.accesses)
      if (a.kind != AccessRecord::kRelease) use.emplace(std::pair{a.a, a.b}, 0);
  {
    std::uint32_t last = CallRecord::kNone, n = 0;
    for (auto& [k, v] : use) {
      n = k.first == last ? n + 1 : 0;
      last = k.first;
      v = n;
    }
  }
  auto wait_name = [&](const AccessRecord& a) {
    return "wait " + std::to_string(a.a) + " use " + std::to_string(use.at({a.a, a.b}));
  };
  std::vector<Access> acc;
  for (const SegmentRecord* s : order) {
    const CallRecord& c = *calls.at(s->call);
    acc.clear();
    if (s->seg > 0) {
      acc.push_back({datum(0, s->call, s->seg - 1,
                           [&] { return label(c) + " part " + std::to_string(s->seg - 1); }),
                     AccessMode::R});
    } else {
      if (c.poster_call != CallRecord::kNone && calls.count(c.poster_call))
        acc.push_back({datum(0, c.poster_call, c.poster_seg,
                             [&] {
                               return label(*calls.at(c.poster_call)) + " part " +
                                      std::to_string(c.poster_seg);
                             }),
                       AccessMode::R});
      if (released.count(c.id))
        acc.push_back({datum(1, c.id, 0, [&] { return label(c) + " released"; }), AccessMode::R});
    }
    for (std::uint32_t i = 0; i < s->access_count; ++i) {
      const AccessRecord& a = access_base.at(s)[s->access_begin + i];
      switch (a.kind) {
        case AccessRecord::kRelease:
          if (calls.count(a.a))
            acc.push_back({datum(1, a.a, 0, [&] { return label(*calls.at(a.a)) + " released"; }),
                           AccessMode::CW});
          break;
        case AccessRecord::kSignal:
          acc.push_back({datum(2, a.a, a.b, [&] { return wait_name(a); }), AccessMode::CW});
          break;
        case AccessRecord::kWaitRead:
          if (signalled.count((std::uint64_t{a.a} << 32) | a.b))
            acc.push_back({datum(2, a.a, a.b, [&] { return wait_name(a); }), AccessMode::R});
          break;
      }
    }
    if (!s->last)
      acc.push_back(
          {datum(0, s->call, s->seg, [&] { return label(c) + " part " + std::to_string(s->seg); }),
           AccessMode::W});
    const KindId kind = g.intern_kind(c.name);
    const auto cost = static_cast<std::uint64_t>(
        std::max(static_cast<double>(s->end - s->start) * log.ns_per_tick + 0.5, 1.0));
    g.add_task(kind, kNoObject, acc, cost, segment_key(c.key, s->seg));
  }
  g.derive_edges();
  return g;
}

}  // namespace tgraph::ode::detail
