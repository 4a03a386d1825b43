// SPDX-License-Identifier: MIT
// The step's schedule across ranks: a walk over the unrolled step in program order that
// follows, on every rank, which version of each datum its copy holds.
#include "tgraph/mpi/schedule.hpp"

#include <algorithm>

namespace tgraph::mpi {

std::uint64_t wire_bytes(const Datum& d) {
  return std::max<std::uint64_t>(1, (d.bytes + 7) / 8 * 8);
}

std::uint64_t Traffic::total_messages() const {
  std::uint64_t s = 0;
  for (auto v : messages) s += v;
  return s;
}
std::uint64_t Traffic::total_bytes() const {
  std::uint64_t s = 0;
  for (auto v : bytes) s += v;
  return s;
}
std::uint64_t Traffic::total_decisions() const {
  std::uint64_t s = 0;
  for (auto v : decisions) s += v;
  return s;
}
void Traffic::add(const Traffic& o) {
  for (std::size_t i = 0; i < messages.size() && i < o.messages.size(); ++i) {
    messages[i] += o.messages[i];
    bytes[i] += o.bytes[i];
    decisions[i] += o.decisions[i];
  }
  entering_messages += o.entering_messages;
  entering_bytes += o.entering_bytes;
}

std::uint32_t Holders::first(DatumId d) const {
  for (std::uint32_t r = 0; r < ranks; ++r)
    if (holds(d, r)) return r;
  return 0;
}

void Holders::grow(std::size_t n, std::size_t from) {
  has.resize(n * ranks, 0);
  for (std::size_t i = from * ranks; i < n * ranks; ++i) has[i] = 1;
}

Holders everywhere(std::size_t data, std::uint32_t ranks) {
  Holders h;
  h.ranks = ranks;
  h.grow(data, 0);
  return h;
}

std::uint32_t ChannelTable::get(const Channel& c) {
  const auto key = std::make_tuple(c.decision, c.source, c.what, c.from, c.to);
  if (auto it = index_.find(key); it != index_.end()) return it->second;
  const auto id = static_cast<std::uint32_t>(channels_.size());
  channels_.push_back(c);
  index_.emplace(key, id);
  return id;
}

namespace {

constexpr std::int64_t kEntering = -1;  // the version from before the step
constexpr std::int64_t kStale = -2;     // an older version

// One rank's copy of one datum.
struct Copy {
  std::int64_t version = kEntering;
  bool has_producer = false;
  Wait producer;                       // what made this copy current
  std::vector<std::uint32_t> readers;  // local readers of this version
  std::uint32_t zero_pending = kNone;  // sender instance: reset to zero once the reducer ran
};

// Whether an access's result depends on the datum's previous contents: reads, and CW (it
// adds to them).
bool uses_value(AccessMode m) { return m != AccessMode::W; }

}  // namespace

StepSchedule schedule_step(const ExecGraph& x, const StepGraph& step, const Layout& layout,
                           const Holders& before_in, ChannelTable& channels) {
  const StepGraph& g = x.graph;
  const std::uint32_t R = layout.ranks;
  const std::size_t nd = g.data.size();
  const std::size_t n_orig = step.data.size();
  Holders before = before_in;
  before.ranks = R;
  if (before.has.size() < n_orig * R) before.grow(n_orig, before.has.size() / R);
  auto is_temp = [&](DatumId d) { return x.datum_origin[d] != d; };

  StepSchedule s;
  s.traffic = Traffic(R);
  s.programs.assign(layout.processors(), {});
  std::vector<Copy> copies(nd * R);
  for (DatumId d = 0; d < nd; ++d)
    for (std::uint32_t r = 0; r < R; ++r)
      copies[d * R + r].version = (is_temp(d) || before.holds(d, r)) ? kEntering : kStale;
  std::vector<std::int64_t> cur(nd, kEntering);

  auto proc_of = [&](TaskId t) -> ProcId { return x.assignment.proc[t]; };
  auto run_instance = [&](TaskId t, std::uint32_t iteration) {
    const auto id = static_cast<std::uint32_t>(s.instances.size());
    Instance inst;
    inst.task = t;
    inst.iteration = iteration;
    inst.proc = proc_of(t);
    const std::uint32_t r = layout.rank_of(inst.proc);
    auto add_wait = [&](Wait w) {
      if (w.kind == WaitKind::kInstance &&
          (w.index == id || s.instances[w.index].proc == inst.proc))
        return;  // program order on this processor
      for (const Wait& o : inst.waits)
        if (o.kind == w.kind && o.index == w.index) return;
      inst.waits.push_back(w);
    };
    const auto accesses = g.accesses_of(t);
    for (const Access& a : accesses) {
      if (!uses_value(a.mode)) continue;
      Copy& c = copies[a.datum * R + r];
      if (c.version != cur[a.datum]) {
        Message m;
        m.datum = a.datum;
        m.to = r;
        m.bytes = wire_bytes(g.data[a.datum]);
        const bool entering = cur[a.datum] == kEntering;
        m.source = entering ? kNone : static_cast<std::uint32_t>(cur[a.datum]);
        m.from = entering ? before.first(x.datum_origin[a.datum])
                          : layout.rank_of(s.instances[m.source].proc);
        Channel ch;
        ch.source = entering ? kNoTask : s.instances[m.source].task;
        ch.what = a.datum;
        ch.from = m.from;
        ch.to = r;
        ch.bytes = m.bytes;
        m.channel = channels.get(ch);
        m.hazards = c.readers;
        if (c.has_producer && c.producer.kind == WaitKind::kInstance)
          m.hazards.push_back(c.producer.index);
        if (is_temp(a.datum) && !entering) {
          m.zero_after_send = true;
          copies[a.datum * R + m.from].zero_pending = m.source;
        }
        const auto mid = static_cast<std::uint32_t>(s.messages.size());
        s.traffic.messages[m.from * R + r] += 1;
        s.traffic.bytes[m.from * R + r] += m.bytes;
        if (entering) {
          s.entering.push_back(mid);
          s.traffic.entering_messages += 1;
          s.traffic.entering_bytes += m.bytes;
        } else {
          s.instances[m.source].sends.push_back(mid);
        }
        s.messages.push_back(std::move(m));
        c = Copy{cur[a.datum], true, Wait{WaitKind::kMessage, mid}, {}, kNone};
      }
      if (c.has_producer) add_wait(c.producer);
    }
    for (const Access& a : accesses) {
      if (!writes(a.mode)) continue;
      Copy& c = copies[a.datum * R + r];
      for (std::uint32_t rd : c.readers) add_wait(Wait{WaitKind::kInstance, rd});
      if (c.has_producer) add_wait(c.producer);
      cur[a.datum] = id;
      c = Copy{id, true, Wait{WaitKind::kInstance, id}, {}, kNone};
      if (is_temp(a.datum) && x.origin[t] == kNoTask) {
        // The reducer resets the temporary; the senders reset their copies when they sent.
        for (std::uint32_t r2 = 0; r2 < R; ++r2) {
          Copy& o = copies[a.datum * R + r2];
          if (r2 == r || o.zero_pending == kNone) continue;
          o = Copy{id, true, Wait{WaitKind::kInstance, o.zero_pending}, {}, kNone};
        }
      }
    }
    for (const Access& a : accesses)
      if (a.mode == AccessMode::R) copies[a.datum * R + r].readers.push_back(id);
    s.programs[inst.proc].push_back(ProgramItem{false, id});
    s.instances.push_back(std::move(inst));
    return id;
  };

  std::vector<LoopId> loop_at(g.tasks.size(), kNoLoop);
  for (LoopId l = 0; l < g.loops.size(); ++l) loop_at[g.loops[l].first] = l;
  for (TaskId t = 0; t < g.tasks.size();) {
    const LoopId l = loop_at[t];
    if (l == kNoLoop) {
      run_instance(t, 0);
      ++t;
      continue;
    }
    const Loop& loop = g.loops[l];
    const std::uint32_t n = std::max<std::uint32_t>(1, step.loops[l].iterations);
    const ProcId decider = proc_of(loop.last - 1);
    std::vector<bool> in_body(layout.processors(), false);
    for (TaskId u = loop.first; u < loop.last; ++u) in_body[proc_of(u)] = true;
    std::vector<std::uint32_t> to;
    for (std::uint32_t r = 0; r < R; ++r) {
      bool any = false;
      for (ProcId p = r * layout.threads_per_rank; p < (r + 1) * layout.threads_per_rank; ++p)
        any = any || in_body[p];
      if (any && r != layout.rank_of(decider)) to.push_back(r);
    }
    auto wait_decision = [&](std::uint32_t k) {
      for (ProcId p = 0; p < layout.processors(); ++p)
        if (in_body[p] && p != decider) s.programs[p].push_back(ProgramItem{true, k});
    };
    for (std::uint32_t i = 0; i < n; ++i) {
      if (i > 0) wait_decision(static_cast<std::uint32_t>(s.decisions.size() - 1));
      std::uint32_t brk = 0;
      for (TaskId u = loop.first; u < loop.last; ++u) brk = run_instance(u, i);
      Decision dec;
      dec.loop = l;
      dec.iteration = i;
      dec.stop = i + 1 == n;
      dec.from = layout.rank_of(decider);
      dec.to = to;
      for (std::uint32_t r : to) {
        Channel ch;
        ch.decision = true;
        ch.what = l;
        ch.from = dec.from;
        ch.to = r;
        ch.bytes = kDecisionBytes;
        dec.channels.push_back(channels.get(ch));
        s.traffic.decisions[dec.from * R + r] += 1;
      }
      s.instances[brk].decision = static_cast<std::uint32_t>(s.decisions.size());
      s.decisions.push_back(std::move(dec));
    }
    wait_decision(static_cast<std::uint32_t>(s.decisions.size() - 1));
    t = loop.last;
  }

  s.holders_after.ranks = R;
  s.holders_after.has.assign(n_orig * R, 0);
  for (DatumId d = 0; d < n_orig; ++d)
    for (std::uint32_t r = 0; r < R; ++r)
      s.holders_after.has[d * R + r] = copies[d * R + r].version == cur[d] ? 1 : 0;
  return s;
}

Traffic predict_traffic(const ExecGraph& x, const StepGraph& step, const Layout& layout,
                        const Holders& before) {
  ChannelTable channels;
  return schedule_step(x, step, layout, before, channels).traffic;
}

}  // namespace tgraph::mpi
