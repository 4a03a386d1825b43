// SPDX-License-Identifier: MIT
#include "tgraph/graph/access_check.hpp"

#include <algorithm>
#include <cstring>

namespace tgraph {
namespace {

constexpr std::uint64_t kMul = 0x9fb21c651e98df25ull;

inline std::uint64_t mix(std::uint64_t h, std::uint64_t w) {
  h = (h ^ w) * kMul;  // a bijection of h ^ w (kMul is odd) ...
  return h ^ (h >> 29);  // ... and another: a changed word always changes the lane
}

}  // namespace

std::string_view to_string(AccessFound found) {
  switch (found) {
    case AccessFound::kWrite: return "write";
    case AccessFound::kRead: return "read";
  }
  return "?";
}

std::string to_string(const AccessFinding& f) {
  return "task " + f.task + (f.found == AccessFound::kWrite ? " wrote " : " read ") + f.datum +
         ", declared " + f.declared;
}

AccessFinding finding(std::string task, const AccessChecker::Found& f, std::span<const Datum> data) {
  AccessFinding a;
  a.task = std::move(task);
  a.datum = f.datum == AccessChecker::kOutsideState ? "(state outside the declared data)"
            : f.datum < data.size()               ? data[f.datum].name
                                                  : "datum " + std::to_string(f.datum);
  a.found = f.found;
  a.declared = f.declared ? std::string(to_string(*f.declared)) : "none";
  return a;
}

std::string task_label(std::string_view kind, std::string_view object, std::uint32_t occurrence) {
  std::string s(kind);
  if (!object.empty()) s += " of " + std::string(object);
  if (occurrence > 0) s += " #" + std::to_string(occurrence);
  return s;
}

std::string task_label(const StepGraph& g, TaskId t) {
  const Task& task = g.tasks[t];
  std::uint32_t occurrence = 0;
  for (TaskId u = 0; u < t; ++u)
    if (g.tasks[u].kind == task.kind && g.tasks[u].object == task.object) ++occurrence;
  const std::string_view kind =
      task.kind < g.kinds.size() ? std::string_view(g.kinds[task.kind]) : std::string_view("?");
  const std::string_view object = task.object != kNoObject && task.object < g.objects.size()
                                      ? std::string_view(g.objects[task.object].name)
                                      : std::string_view();
  return task_label(kind, object, occurrence);
}

std::uint64_t AccessChecker::checksum(const void* ptr, std::uint64_t bytes) {
  const auto* p = static_cast<const unsigned char*>(ptr);
  std::uint64_t h[4] = {0x243f6a8885a308d3ull, 0x13198a2e03707344ull, 0xa4093822299f31d0ull,
                        0x082efa98ec4e6c89ull};
  std::uint64_t i = 0;
  for (; i + 32 <= bytes; i += 32) {  // four independent lanes: memory-bound, not latency-bound
    std::uint64_t w[4];
    std::memcpy(w, p + i, 32);
    for (int l = 0; l < 4; ++l) h[l] = mix(h[l], w[l]);
  }
  for (; i + 8 <= bytes; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    h[0] = mix(h[0], w);
  }
  if (i < bytes) {
    std::uint64_t w = 0;
    std::memcpy(&w, p + i, bytes - i);
    h[1] = mix(h[1], w);
  }
  std::uint64_t s = mix(h[0], bytes);
  for (int l = 1; l < 4; ++l) s = mix(s, h[l]);
  return s;
}

void AccessChecker::perturb(void* ptr, std::uint64_t bytes) {
  auto* p = static_cast<unsigned char*>(ptr);
  for (std::uint64_t i = 0; i + 8 <= bytes; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    const std::uint64_t exponent = (w >> 52) & 0x7ff;
    if (exponent == 0 || exponent == 0x7ff) continue;  // zero, denormal (small integer), NaN
    w ^= std::uint64_t{1} << 40;
    std::memcpy(p + i, &w, 8);
  }
}

void AccessChecker::set_storage(DatumId d, void* ptr, std::uint64_t bytes) {
  if (regions_.size() <= d) regions_.resize(static_cast<std::size_t>(d) + 1);
  regions_[d] = Region{ptr, ptr ? bytes : 0, 0};
}

void AccessChecker::clear_storage() { regions_.clear(); }

void AccessChecker::sync() {
  for (Region& r : regions_)
    if (r.ptr) r.sum = checksum(r.ptr, r.bytes);
}

void AccessChecker::sync(DatumId d) {
  if (has_storage(d)) regions_[d].sum = checksum(regions_[d].ptr, regions_[d].bytes);
}

void AccessChecker::save(const std::vector<DatumId>& ds, std::vector<unsigned char>& into) const {
  std::size_t n = 0;
  for (DatumId d : ds) n += regions_[d].bytes;
  into.resize(n);
  std::size_t at = 0;
  for (DatumId d : ds) {
    if (regions_[d].bytes) std::memcpy(into.data() + at, regions_[d].ptr, regions_[d].bytes);
    at += regions_[d].bytes;
  }
}

void AccessChecker::restore(const std::vector<DatumId>& ds, const std::vector<unsigned char>& from) {
  std::size_t at = 0;
  for (DatumId d : ds) {
    if (regions_[d].bytes) std::memcpy(regions_[d].ptr, from.data() + at, regions_[d].bytes);
    at += regions_[d].bytes;
  }
}

bool AccessChecker::same(const std::vector<DatumId>& ds, const std::vector<unsigned char>& as) const {
  std::size_t at = 0;
  for (DatumId d : ds) {
    if (regions_[d].bytes && std::memcmp(regions_[d].ptr, as.data() + at, regions_[d].bytes) != 0)
      return false;
    at += regions_[d].bytes;
  }
  return true;
}

bool AccessChecker::differs_with(BodyRef body, const std::vector<DatumId>& outputs,
                                 const std::vector<unsigned char>& before,
                                 const std::vector<unsigned char>& after,
                                 std::span<const DatumId> perturbed) {
  restore(outputs, before);
  for (DatumId d : perturbed) perturb(regions_[d].ptr, regions_[d].bytes);
  bool threw = false;
  try {
    body();
  } catch (...) {
    threw = true;  // the perturbed value reached the body's checks: it was read
  }
  ++counts_.reruns;
  for (DatumId d : perturbed) perturb(regions_[d].ptr, regions_[d].bytes);  // undone
  return threw || !same(outputs, after);
}

void AccessChecker::find_reads(BodyRef body, const std::vector<DatumId>& outputs,
                               const std::vector<unsigned char>& before,
                               const std::vector<unsigned char>& after,
                               std::span<const DatumId> set, std::vector<DatumId>& read) {
  if (set.size() == 1) {
    read.push_back(set[0]);
    return;
  }
  const std::span<const DatumId> a = set.first(set.size() / 2), b = set.subspan(set.size() / 2);
  const bool in_a = differs_with(body, outputs, before, after, a);
  const bool in_b = differs_with(body, outputs, before, after, b);
  if (in_a) find_reads(body, outputs, before, after, a, read);
  if (in_b) find_reads(body, outputs, before, after, b, read);
  if (!in_a && !in_b) read.insert(read.end(), set.begin(), set.end());  // only together
}

void AccessChecker::run(std::span<const Access> acc, BodyRef body, bool check_reads,
                        std::vector<Found>& out) {
  ++counts_.runs;
  auto declared = [&acc](DatumId d) {
    std::optional<AccessMode> m;
    for (const Access& a : acc)
      if (a.datum == d && (!m || writes(a.mode))) m = a.mode;
    return m;
  };
  // The data the task may write; its reads are checked only when all of them have storage.
  std::vector<DatumId> outputs;
  bool restorable = true;
  for (const Access& a : acc) {
    if (!writes(a.mode)) continue;
    if (!has_storage(a.datum)) {
      restorable = false;
    } else if (std::find(outputs.begin(), outputs.end(), a.datum) == outputs.end()) {
      outputs.push_back(a.datum);
    }
  }
  std::vector<unsigned char> before, after;
  if (check_reads && restorable) save(outputs, before);
  body();
  bool wrote_undeclared = false;
  for (DatumId d = 0; d < regions_.size(); ++d) {
    Region& r = regions_[d];
    if (!r.ptr) continue;
    const std::uint64_t s = checksum(r.ptr, r.bytes);
    if (s == r.sum) continue;
    r.sum = s;
    if (std::find(outputs.begin(), outputs.end(), d) != outputs.end()) continue;
    const std::optional<AccessMode> m = declared(d);  // R or nothing: W, RW, CW are outputs
    // Storage shared with a datum the task may write (an alias) is that datum's.
    const auto* lo = static_cast<const unsigned char*>(r.ptr);
    bool alias = false;
    for (DatumId o : outputs) {
      const auto* olo = static_cast<const unsigned char*>(regions_[o].ptr);
      if (lo < olo + regions_[o].bytes && olo < lo + r.bytes) alias = true;
    }
    if (alias) continue;
    out.push_back({d, AccessFound::kWrite, m});
    wrote_undeclared = true;
  }
  if (!check_reads) return;
  if (!restorable || wrote_undeclared) {
    ++counts_.reads_unchecked;
    return;
  }
  std::vector<DatumId> undeclared;
  for (DatumId d = 0; d < regions_.size(); ++d)
    if (regions_[d].ptr && regions_[d].bytes >= 8 && !declared(d)) undeclared.push_back(d);
  if (undeclared.empty() || outputs.empty()) return;
  save(outputs, after);
  if (differs_with(body, outputs, before, after, undeclared)) {
    if (differs_with(body, outputs, before, after, {})) {
      out.push_back({kOutsideState, AccessFound::kRead, std::nullopt});
    } else {
      std::vector<DatumId> read;
      find_reads(body, outputs, before, after, undeclared, read);
      for (DatumId d : read) out.push_back({d, AccessFound::kRead, std::nullopt});
    }
  }
  restore(outputs, after);  // the state the first run left, bit for bit
}

void AccessFindings::add(AccessFinding f) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const AccessFinding& g : list_)
    if (g.task == f.task && g.datum == f.datum && g.found == f.found) return;
  list_.push_back(std::move(f));
}

std::vector<AccessFinding> AccessFindings::list() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return list_;
}

bool AccessFindings::empty() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return list_.empty();
}

}  // namespace tgraph
