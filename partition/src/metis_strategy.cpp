// SPDX-License-Identifier: MIT
// `metis`: METIS 5.1 k-way partitioning of the undirected task graph.
#include <fcntl.h>
#include <metis.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "strategies.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/evaluate.hpp"

static_assert(sizeof(idx_t) == 4, "tgraph expects METIS built with 32-bit idx_t");
static_assert(sizeof(real_t) == sizeof(float), "tgraph expects METIS built with float real_t");

namespace tgraph::partition::detail {

namespace {

// METIS reseeds rand() and installs signal handlers on every call: one caller at a time.
std::mutex& metis_mutex() {
  static std::mutex m;
  return m;
}

// METIS 5.1 prints diagnostics ("***Cannot bisect a graph with 0 vertices!") with printf on
// stdout when K is large for the graph, which would corrupt a JSON report on it: stdout is
// pointed at /dev/null for the duration of the call (under the METIS mutex).
class SilenceStdout {
 public:
  SilenceStdout() {
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) dup2(null, STDOUT_FILENO);
    if (null >= 0) close(null);
  }
  ~SilenceStdout() {
    std::fflush(stdout);
    if (saved_ >= 0) {
      dup2(saved_, STDOUT_FILENO);
      close(saved_);
    }
  }
  SilenceStdout(const SilenceStdout&) = delete;
  SilenceStdout& operator=(const SilenceStdout&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace

std::int64_t metis_kway(const UndirectedGraph& pg, const LibraryWeights& w, std::uint32_t k,
                        const Options& options, std::vector<std::uint32_t>& part) {
  idx_t nvtxs = static_cast<idx_t>(pg.vertices());
  idx_t ncon = static_cast<idx_t>(w.ncon);
  idx_t nparts = static_cast<idx_t>(k);
  std::vector<idx_t> xadj(pg.xadj.begin(), pg.xadj.end());
  std::vector<idx_t> adjncy(pg.adjncy.begin(), pg.adjncy.end());
  std::vector<idx_t> vwgt(w.vwgt.begin(), w.vwgt.end());
  std::vector<idx_t> adjwgt(w.adjwgt.begin(), w.adjwgt.end());
  std::vector<real_t> ubvec(w.ncon, static_cast<real_t>(options.imbalance));
  std::vector<idx_t> out(pg.vertices(), 0);
  idx_t opts[METIS_NOPTIONS];
  METIS_SetDefaultOptions(opts);
  opts[METIS_OPTION_NUMBERING] = 0;
  // Seed 0 keeps METIS's default (-1), so that results equal gpmetis's without -seed.
  if (options.seed != 0) opts[METIS_OPTION_SEED] = static_cast<idx_t>(options.seed % 0x7fffffff);
  opts[METIS_OPTION_OBJTYPE] = options.objective == Objective::kVolume ? METIS_OBJTYPE_VOL : METIS_OBJTYPE_CUT;
  opts[METIS_OPTION_UFACTOR] =
      static_cast<idx_t>(std::lround(std::max(0.0, options.imbalance - 1.0) * 1000.0));
  idx_t objval = 0;
  int status;
  {
    std::lock_guard<std::mutex> lock(metis_mutex());
    SilenceStdout quiet;
    status = METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.empty() ? nullptr : adjncy.data(),
                                 vwgt.data(), nullptr, adjwgt.empty() ? nullptr : adjwgt.data(),
                                 &nparts, nullptr, ubvec.data(), opts, &objval, out.data());
  }
  if (status != METIS_OK)
    throw std::runtime_error("METIS_PartGraphKway failed with status " + std::to_string(status));
  part.resize(pg.vertices());
  for (std::uint32_t v = 0; v < pg.vertices(); ++v) {
    if (out[v] < 0 || out[v] >= nparts)
      throw std::runtime_error("METIS returned part " + std::to_string(out[v]) + " for vertex " +
                               std::to_string(v));
    part[v] = static_cast<std::uint32_t>(out[v]);
  }
  return objval;
}

namespace {

// How far above the step's lower bound the first heavy-loop candidate may be predicted and
// still be kept without partitioning the other two (metis_partition).
constexpr double kCandidateSlack = 0.05;

// METIS k-way on the task graph; optional multi-constraint mode balancing each phase.
Result metis_partition(const StepGraph& g, std::uint32_t k, const Options& options) {
  if (auto trivial = library_trivial_case(g, k)) return *trivial;
  Result r;
  r.assignment.k = k;
  const UndirectedGraph pg = library_graph(g);
  std::vector<std::uint32_t> phase, level;
  std::uint32_t used = 1;
  if (options.phases > 1) {
    level = task_levels(g);
    phase = task_phases(g, level, options.phases, used, options.loop_share);
  }
  std::vector<std::uint32_t> part;
  r.stats.edgecut = metis_kway(pg, library_weights(pg, phase, used), k, options, part);
  if (options.phases > 1 && options.loop_share > 0.0) {
    // Heavy loops as constraints of their own can be more than METIS balances (torso at K = 8:
    // four constraints, imbalance 1.67), and a loop spread over every part pays a hand-off per
    // iteration between all of them: the constraints with one phase for the other tasks, and
    // the level phases alone (the constraints without loops), are partitioned too, and the
    // partition with the shortest simulated step (options.model) is kept: up to three METIS
    // calls and simulations, only on steps with a heavy loop, and the other two only when
    // the first is predicted more than kCandidateSlack above the step's lower bound (no
    // partition beats max(work / K, span) after the host work): a live run partitions on its
    // critical path, and falling64's pile spent 15-44 ms per fallback step on candidates
    // that could not gain more than that.
    std::uint32_t levels_used = 0;
    const std::vector<std::uint32_t> level_phases =
        task_phases(g, level, options.phases, levels_used);
    if (level_phases != phase) {
      // The candidates are compared without the machine's random interruptions: one draw
      // of them is noise, not a difference between the partitions.
      model::CostModel model = options.model;
      model.interruptions.clear();
      const auto predicted = [&](const std::vector<std::uint32_t>& p) {
        Assignment a;
        a.k = k;
        a.proc = p;
        return model::simulate(g, a, model).makespan_ns;
      };
      std::uint64_t best = predicted(part);
      const Metrics metrics = compute_metrics(g);
      const double bound = static_cast<double>(
          step_lower_bound_ns(g.host_ns, metrics.work_ns, metrics.span_ns, k));
      if (static_cast<double>(best) > bound * (1.0 + kCandidateSlack)) {
        std::uint32_t rest_used = 0;
        const std::vector<std::uint32_t> rest_one =
            task_phases(g, level, options.phases, rest_used, options.loop_share, 1);
        const std::pair<const std::vector<std::uint32_t>*, std::uint32_t> alternatives[] = {
            {&rest_one, rest_used}, {&level_phases, levels_used}};
        for (const auto& [alt, n] : alternatives) {
          if (*alt == phase) continue;
          std::vector<std::uint32_t> p;
          const std::int64_t cut = metis_kway(pg, library_weights(pg, *alt, n), k, options, p);
          const std::uint64_t m = predicted(p);
          if (m < best) {
            best = m;
            part = std::move(p);
            r.stats.edgecut = cut;
          }
        }
      }
    }
  }
  r.assignment.proc.assign(part.begin(), part.end());
  return r;
}

/// METIS k-way on the task graph; optional multi-constraint mode balancing each phase.
class Metis final : public Strategy {
 public:
  std::string_view name() const override { return "metis"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&,
                      const Options& options) override {
    return metis_partition(g, k, options);
  }
};

/// METIS from scratch every step (the same call as `metis`), then its K part labels renamed
/// so that as many tasks as possible (matched by stable key, counted once each) keep the
/// previous step's processor: the migration baseline that relabelling alone achieves.
class MetisRelabel final : public Strategy {
 public:
  std::string_view name() const override { return "metis-relabel"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                      const Options& options) override {
    Result r = metis_partition(g, k, options);
    r.assignment.k = k;
    relabel_to_previous(g, prev, r.assignment);
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_metis() { return std::make_unique<Metis>(); }
std::unique_ptr<Strategy> make_metis_relabel() { return std::make_unique<MetisRelabel>(); }

}  // namespace tgraph::partition::detail
