// SPDX-License-Identifier: MIT
// PT-Scotch into nodes, then Scotch within each node. Scotch's headers come after <stdint.h>,
// <stdio.h> and <mpi.h>, by their scotch/ prefix only (/usr/include/scotch holds a metis.h
// that must never shadow METIS's).
#include "tgraph/mpi/ptscotch.hpp"

#include <mpi.h>
#include <scotch/ptscotch.h>
#include <stdint.h>
#include <stdio.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/graph/undirected.hpp"
#include "tgraph/mpi/session.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/partition_graph.hpp"

static_assert(sizeof(SCOTCH_Num) == 4, "tgraph expects PT-Scotch built with 32-bit SCOTCH_Num");

namespace tgraph::mpi {

namespace {

/// First task of rank r's slice.
std::uint32_t slice_begin(std::uint32_t n, int rank, int ranks) {
  return static_cast<std::uint32_t>(static_cast<std::uint64_t>(n) *
                                    static_cast<std::uint64_t>(rank) /
                                    static_cast<std::uint64_t>(ranks));
}

/// The factor make_undirected scales weights by when their total exceeds `max_total`
/// (1 when it does not), and the scaling itself, so that every rank's slice carries the
/// weights partition::library_graph gives the whole graph.
long double scale_factor(long double total, std::int64_t max_total) {
  return total <= static_cast<long double>(max_total) ? 1.0L
                                                      : static_cast<long double>(max_total) / total;
}
void scale(std::vector<std::int64_t>& w, long double f) {
  if (f == 1.0L) return;
  for (auto& x : w)
    x = std::max<std::int64_t>(
        1, static_cast<std::int64_t>(std::llround(static_cast<long double>(x) * f)));
}

long double sum_all(long double local, MPI_Comm comm) {
  long double total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_LONG_DOUBLE, MPI_SUM, comm);
  return total;
}

double max_all(double local, MPI_Comm comm) {
  double m = 0;
  MPI_Allreduce(&local, &m, 1, MPI_DOUBLE, MPI_MAX, comm);
  return m;
}

/// Rank r's slice [begin, begin + vertices()) of the undirected graph: xadj local, adjncy
/// global task ids, weights as library_graph makes them (parallel edges merged, scaled).
struct Slice {
  std::uint32_t begin = 0;
  UndirectedGraph g;
};

Slice build_slice(const StepGraph& sg, int rank, int ranks, MPI_Comm comm) {
  const auto n = static_cast<std::uint32_t>(sg.tasks.size());
  Slice s;
  s.begin = slice_begin(n, rank, ranks);
  const std::uint32_t end = slice_begin(n, rank + 1, ranks);
  struct Half {
    std::uint32_t u, v;
    std::int64_t w;
  };
  std::vector<Half> halves;
  auto add = [&](const Edge& e) {
    if (e.from == e.to) return;
    const std::int64_t w =
        std::max<std::int64_t>(1, static_cast<std::int64_t>(sg.data[e.datum].bytes));
    if (e.from >= s.begin && e.from < end) halves.push_back({e.from, e.to, w});
    if (e.to >= s.begin && e.to < end) halves.push_back({e.to, e.from, w});
  };
  for (const Edge& e : sg.edges) add(e);
  for (const Edge& e : sg.carried_edges) add(e);
  std::sort(halves.begin(), halves.end(),
            [](const Half& a, const Half& b) { return a.u != b.u ? a.u < b.u : a.v < b.v; });
  UndirectedGraph& g = s.g;
  g.xadj.assign(end - s.begin + 1, 0);
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i;
    std::int64_t w = 0;
    while (j < halves.size() && halves[j].u == halves[i].u && halves[j].v == halves[i].v)
      w += halves[j++].w;
    g.adjncy.push_back(halves[i].v);
    g.adjwgt.push_back(w);
    ++g.xadj[halves[i].u - s.begin + 1];
    i = j;
  }
  for (std::uint32_t i = 0; i + 1 < g.xadj.size(); ++i) g.xadj[i + 1] += g.xadj[i];
  g.vwgt.resize(end - s.begin);
  for (TaskId t = s.begin; t < end; ++t)
    g.vwgt[t - s.begin] =
        std::max<std::int64_t>(1, static_cast<std::int64_t>(sg.tasks[t].cost_ns * sg.runs(t)));
  // The totals of the whole graph decide the scaling, as in make_undirected.
  const long double vtotal = sum_all(std::accumulate(g.vwgt.begin(), g.vwgt.end(), 0.0L), comm);
  const long double etotal = sum_all(std::accumulate(g.adjwgt.begin(), g.adjwgt.end(), 0.0L), comm);
  scale(g.vwgt, scale_factor(vtotal, partition::kMaxLibraryWeight));
  scale(g.adjwgt, scale_factor(etotal, 2 * partition::kMaxLibraryWeight));
  return s;
}

/// SCOTCH_dgraphPart of the slices into `nodes` parts; returns the node of each local task.
std::vector<std::uint32_t> partition_nodes(const Slice& s, const partition::LibraryWeights& w,
                                           std::uint32_t nodes, const partition::Options& options,
                                           MPI_Comm comm) {
  const std::uint32_t nloc = s.g.vertices();
  std::vector<std::uint32_t> node(nloc, 0);
  if (nodes <= 1) return node;
  std::vector<SCOTCH_Num> vert(s.g.xadj.begin(), s.g.xadj.end());
  std::vector<SCOTCH_Num> edge(s.g.adjncy.begin(), s.g.adjncy.end());
  std::vector<SCOTCH_Num> velo(w.vwgt.begin(), w.vwgt.end());
  std::vector<SCOTCH_Num> edlo(w.adjwgt.begin(), w.adjwgt.end());
  // PT-Scotch wants valid pointers even for empty arrays.
  const auto arcs = static_cast<SCOTCH_Num>(edge.size());
  edge.push_back(0);
  edlo.push_back(1);
  velo.push_back(1);
  std::vector<SCOTCH_Num> part(static_cast<std::size_t>(nloc) + 1, 0);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);

  SCOTCH_Dgraph dg;
  if (SCOTCH_dgraphInit(&dg, comm) != 0) throw std::runtime_error("SCOTCH_dgraphInit failed");
  SCOTCH_Strat strat;
  SCOTCH_stratInit(&strat);
  int status = SCOTCH_dgraphBuild(&dg, 0, static_cast<SCOTCH_Num>(nloc),
                                  static_cast<SCOTCH_Num>(nloc), vert.data(), nullptr, velo.data(),
                                  nullptr, arcs, arcs, edge.data(), nullptr, edlo.data());
  const char* what = "SCOTCH_dgraphBuild failed";
#if defined(TGRAPH_ENABLE_ASSERT)
  if (status == 0 && SCOTCH_dgraphCheck(&dg) != 0) {
    status = 1;
    what = "SCOTCH_dgraphCheck rejected the distributed graph";
  }
#endif
  if (status == 0) {
    status =
        SCOTCH_stratDgraphMapBuild(&strat, partition::scotch_strategy_flags(options.scotch), ranks,
                                   static_cast<SCOTCH_Num>(nodes), options.imbalance - 1.0);
    what = "SCOTCH_stratDgraphMapBuild failed";
  }
  if (status == 0) {
    SCOTCH_randomSeed(static_cast<SCOTCH_Num>(options.seed % 0x7fffffff));
    SCOTCH_randomReset();
    status = SCOTCH_dgraphPart(&dg, static_cast<SCOTCH_Num>(nodes), &strat, part.data());
    what = "SCOTCH_dgraphPart failed";
  }
  SCOTCH_stratExit(&strat);
  SCOTCH_dgraphExit(&dg);
  // A failure is collective in PT-Scotch; agree anyway so that no rank goes on alone.
  int failed = status != 0 ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, comm);
  if (failed != 0)
    throw std::runtime_error(status != 0 ? what : "PT-Scotch failed on another rank");
  for (std::uint32_t v = 0; v < nloc; ++v) {
    if (part[v] < 0 || static_cast<std::uint32_t>(part[v]) >= nodes)
      throw std::runtime_error("PT-Scotch returned node " + std::to_string(part[v]) + " for task " +
                               std::to_string(s.begin + v));
    node[v] = static_cast<std::uint32_t>(part[v]);
  }
  return node;
}

/// Every rank's `local` concatenated in rank order (MPI_Allgatherv of 32-bit values).
std::vector<std::uint32_t> all_gather(const std::vector<std::uint32_t>& local, MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  std::vector<int> counts(static_cast<std::size_t>(ranks)),
      displs(static_cast<std::size_t>(ranks), 0);
  const int mine = static_cast<int>(local.size());
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<std::uint32_t> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(local.data(), mine, MPI_UINT32_T, all.data(), counts.data(), displs.data(),
                 MPI_UINT32_T, comm);
  return all;
}

/// Sends `out[r]` to rank r, returns what every rank sent here, in rank order.
std::vector<std::uint32_t> all_to_all(const std::vector<std::vector<std::uint32_t>>& out,
                                      MPI_Comm comm) {
  const auto ranks = static_cast<int>(out.size());
  std::vector<int> scount(out.size()), sdispl(out.size(), 0), rcount(out.size()),
      rdispl(out.size(), 0);
  for (int r = 0; r < ranks; ++r) scount[r] = static_cast<int>(out[r].size());
  MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) {
    sdispl[r] = sdispl[r - 1] + scount[r - 1];
    rdispl[r] = rdispl[r - 1] + rcount[r - 1];
  }
  std::vector<std::uint32_t> send;
  send.reserve(static_cast<std::size_t>(sdispl.back() + scount.back()));
  for (const auto& o : out) send.insert(send.end(), o.begin(), o.end());
  std::vector<std::uint32_t> recv(static_cast<std::size_t>(rdispl.back() + rcount.back()));
  MPI_Alltoallv(send.data(), scount.data(), sdispl.data(), MPI_UINT32_T, recv.data(), rcount.data(),
                rdispl.data(), MPI_UINT32_T, comm);
  return recv;
}

/// Sends each node's induced subgraph to rank node mod R, which partitions it over `cores`
/// with sequential Scotch; returns (task, processor) pairs of the tasks this rank placed.
std::vector<std::uint32_t> partition_cores(const Slice& s, const partition::LibraryWeights& w,
                                           const std::vector<std::uint32_t>& node_of,
                                           std::uint32_t cores, const partition::Options& options,
                                           MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  // Records: task, weight, degree, then (neighbour, weight) pairs inside the same node.
  std::vector<std::vector<std::uint32_t>> out(static_cast<std::size_t>(ranks));
  for (std::uint32_t v = 0; v < s.g.vertices(); ++v) {
    const std::uint32_t t = s.begin + v;
    auto& o = out[node_of[t] % static_cast<std::uint32_t>(ranks)];
    o.push_back(t);
    o.push_back(static_cast<std::uint32_t>(w.vwgt[v]));
    const std::size_t degree_at = o.size();
    o.push_back(0);
    for (std::uint32_t i = s.g.xadj[v]; i < s.g.xadj[v + 1]; ++i) {
      const std::uint32_t u = s.g.adjncy[i];
      if (node_of[u] != node_of[t]) continue;
      o.push_back(u);
      o.push_back(static_cast<std::uint32_t>(w.adjwgt[i]));
      ++o[degree_at];
    }
  }
  const std::vector<std::uint32_t> in = all_to_all(out, comm);
  out.clear();
  // Tasks received, by node: offsets of their records.
  struct Vertex {
    std::uint32_t task;
    std::size_t record;
  };
  std::vector<std::vector<Vertex>> by_node;
  for (std::size_t i = 0; i < in.size(); i += 3 + 2 * static_cast<std::size_t>(in[i + 2])) {
    const std::uint32_t node = node_of[in[i]];
    const std::uint32_t slot = node / static_cast<std::uint32_t>(ranks);
    if (by_node.size() <= slot) by_node.resize(slot + 1);
    by_node[slot].push_back({in[i], i});
  }
  std::vector<std::uint32_t> placed;
  for (auto& vs : by_node) {
    if (vs.empty()) continue;
    std::sort(vs.begin(), vs.end(),
              [](const Vertex& a, const Vertex& b) { return a.task < b.task; });
    const std::uint32_t node = node_of[vs.front().task];
    auto local = [&](std::uint32_t task) {
      return static_cast<std::uint32_t>(
          std::lower_bound(vs.begin(), vs.end(), task,
                           [](const Vertex& a, std::uint32_t t) { return a.task < t; }) -
          vs.begin());
    };
    // The node's subgraph, renumbered; neighbour lists sorted as UndirectedGraph keeps them.
    UndirectedGraph sub;
    sub.xadj.assign(vs.size() + 1, 0);
    sub.vwgt.resize(vs.size());
    for (std::size_t v = 0; v < vs.size(); ++v) {
      const std::size_t r = vs[v].record;
      sub.vwgt[v] = in[r + 1];
      sub.xadj[v + 1] = sub.xadj[v] + in[r + 2];
      for (std::uint32_t j = 0; j < in[r + 2]; ++j) {
        sub.adjncy.push_back(local(in[r + 3 + 2 * j]));
        sub.adjwgt.push_back(in[r + 4 + 2 * j]);
      }
    }
    const std::vector<std::uint32_t> core =
        partition::scotch_partition(sub, partition::library_weights(sub), cores, options);
    for (std::size_t v = 0; v < vs.size(); ++v) {
      placed.push_back(vs[v].task);
      placed.push_back(node * cores + core[v]);
    }
  }
  return placed;
}

/// max / mean of `load` (1 when it sums to zero).
double imbalance(const std::vector<std::int64_t>& load) {
  const long double total = std::accumulate(load.begin(), load.end(), 0.0L);
  if (total <= 0) return 1.0;
  const long double mean = total / static_cast<long double>(load.size());
  return static_cast<double>(static_cast<long double>(*std::max_element(load.begin(), load.end())) /
                             mean);
}

}  // namespace

PtScotchResult ptscotch_partition(const StepGraph& g, std::uint32_t nodes, std::uint32_t cores,
                                  const partition::Options& options, MPI_Comm comm) {
  if (nodes == 0) throw OptionError("nodes", "expected at least 1");
  if (cores == 0) throw OptionError("cores", "expected at least 1");
  // Debian's Scotch is multi-threaded with thread pinning: one thread per rank.
  setenv("SCOTCH_PTHREAD_NUMBER", "1", 0);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const double t0 = MPI_Wtime();
  PtScotchResult r;
  r.nodes = nodes;
  r.cores = cores;
  r.vertices = g.tasks.size();

  const Slice s = build_slice(g, rank, ranks, comm);
  const partition::LibraryWeights w = partition::library_weights(s.g);
  // Each level gets the square root of the tolerance, so that node x core imbalance stays
  // within `options.imbalance`, as for sequential Scotch at K = nodes x cores.
  partition::Options level = options;
  const bool two_levels = nodes > 1 && cores > 1;
  if (two_levels) level.imbalance = std::sqrt(options.imbalance);
  const double t1 = MPI_Wtime();
  const std::vector<std::uint32_t> node_of =
      all_gather(partition_nodes(s, w, nodes, level, comm), comm);
  const double t2 = MPI_Wtime();
  const std::vector<std::uint32_t> placed =
      all_gather(partition_cores(s, w, node_of, cores, level, comm), comm);
  const double t3 = MPI_Wtime();

  const std::uint32_t k = nodes * cores;
  r.assignment.k = k;
  r.assignment.proc.assign(g.tasks.size(), k);
  for (std::size_t i = 0; i + 1 < placed.size(); i += 2)
    r.assignment.proc[placed[i]] = placed[i + 1];
  for (std::size_t t = 0; t < r.assignment.proc.size(); ++t)
    if (r.assignment.proc[t] >= k)
      throw std::runtime_error("ptscotch: task " + std::to_string(t) + " was not placed");

  // Cut, loads and edges from the slices: each undirected edge counted by its smaller end.
  std::int64_t stats[3] = {0, 0, 0};  // cut, node cut, edges
  std::vector<std::int64_t> load(k, 0);
  for (std::uint32_t v = 0; v < s.g.vertices(); ++v) {
    const std::uint32_t t = s.begin + v;
    load[r.assignment.proc[t]] += w.vwgt[v];
    for (std::uint32_t i = s.g.xadj[v]; i < s.g.xadj[v + 1]; ++i) {
      const std::uint32_t u = s.g.adjncy[i];
      if (u < t) continue;
      ++stats[2];
      if (r.assignment.proc[u] != r.assignment.proc[t]) stats[0] += w.adjwgt[i];
      if (node_of[u] != node_of[t]) stats[1] += w.adjwgt[i];
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, stats, 3, MPI_INT64_T, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, load.data(), static_cast<int>(k), MPI_INT64_T, MPI_SUM, comm);
  r.cut = stats[0];
  r.node_cut = stats[1];
  r.edges = static_cast<std::uint64_t>(stats[2]);
  r.imbalance = imbalance(load);
  std::vector<std::int64_t> node_load(nodes, 0);
  for (std::uint32_t p = 0; p < k; ++p) node_load[p / cores] += load[p];
  r.node_imbalance = imbalance(node_load);
  const double t4 = MPI_Wtime();
  r.build_ms = max_all((t1 - t0) * 1e3, comm);
  r.nodes_ms = max_all((t2 - t1) * 1e3, comm);
  r.cores_ms = max_all((t3 - t2) * 1e3, comm);
  r.total_ms = max_all((t4 - t0) * 1e3, comm);
  return r;
}

PtScotchTraceResult ptscotch_partition_trace(const Trace& trace, std::size_t first,
                                             std::size_t last, std::uint32_t nodes,
                                             std::uint32_t cores, const partition::Options& options,
                                             MPI_Comm comm) {
  PtScotchTraceResult out;
  out.assignment.method = "ptscotch";
  out.assignment.k = nodes * cores;
  for (std::size_t s = first; s < last && s < trace.steps.size(); ++s) {
    const StepGraph& g = trace.steps[s];
    PtScotchResult r = ptscotch_partition(g, nodes, cores, options, comm);
    out.cut += r.cut;
    out.node_cut += r.node_cut;
    out.imbalance = std::max(out.imbalance, r.imbalance);
    out.partition_ms += r.total_ms;
    out.assignment.partition_ms.push_back(r.total_ms);
    out.assignment.steps.push_back(std::move(r.assignment));
    r.assignment = {};
    out.hashes.push_back(g.structural_hash());
    out.steps.push_back(std::move(r));
  }
  return out;
}

std::string ptscotch_json(const PtScotchTraceResult& r, const PtScotchRun& run) {
  nlohmann::json per_step = nlohmann::json::array();
  for (std::size_t i = 0; i < r.steps.size(); ++i) {
    const PtScotchResult& s = r.steps[i];
    per_step.push_back({{"step", run.first + i},
                        {"tasks", s.vertices},
                        {"edges", s.edges},
                        {"cut", s.cut},
                        {"node_cut", s.node_cut},
                        {"imbalance", s.imbalance},
                        {"node_imbalance", s.node_imbalance},
                        {"build_ms", s.build_ms},
                        {"nodes_ms", s.nodes_ms},
                        {"cores_ms", s.cores_ms},
                        {"partition_ms", s.total_ms}});
  }
  return nlohmann::json{{"method", r.assignment.method},
                        {"trace", run.trace},
                        {"output", run.output},
                        {"ranks", run.ranks},
                        {"nodes", run.nodes},
                        {"cores", run.cores},
                        {"k", r.assignment.k},
                        {"steps", r.assignment.steps.size()},
                        {"cut", r.cut},
                        {"node_cut", r.node_cut},
                        {"imbalance", r.imbalance},
                        {"read_ms", run.read_ms},
                        {"partition_ms", r.partition_ms},
                        {"max_rss_mib", run.max_rss_mib},
                        {"per_step", per_step}}
      .dump();
}

std::string ptscotch_text(const PtScotchTraceResult& r, const PtScotchRun& run) {
  std::ostringstream o;
  o << "ptscotch on " << run.ranks << " rank(s): " << r.assignment.steps.size() << " step(s) over "
    << run.nodes << " nodes x " << run.cores << " cores (k = " << r.assignment.k << "): cut "
    << r.cut << " (between nodes " << r.node_cut << "), imbalance " << r.imbalance << ", "
    << r.partition_ms << " ms partitioning\n";
  if (!run.output.empty()) o << "wrote " << run.output << "\n";
  return o.str();
}

PtScotchFileReport ptscotch_partition_file(const PtScotchFileOptions& o, MPI_Comm comm) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const double t0 = MPI_Wtime();
  Trace trace;
  agree_on_input(
      [&] {
        if (o.nodes == 0) throw OptionError("nodes", "expected at least 1");
        if (o.cores == 0) throw OptionError("cores", "expected at least 1");
        trace = read_trace(o.trace);
        if (o.step && *o.step >= trace.steps.size())
          throw OptionError("step", std::to_string(*o.step) + " is past the trace's " +
                                        std::to_string(trace.steps.size()) + " steps");
      },
      comm);
  double read_ms = (MPI_Wtime() - t0) * 1e3;
  MPI_Allreduce(MPI_IN_PLACE, &read_ms, 1, MPI_DOUBLE, MPI_MAX, comm);
  partition::Options options = o.options;
  options.scotch = partition::parse_scotch_flavour(o.scotch);
  const std::size_t first = o.step.value_or(0);
  const std::size_t last = o.step ? *o.step + 1 : trace.steps.size();
  PtScotchFileReport r;
  r.result = ptscotch_partition_trace(trace, first, last, o.nodes, o.cores, options, comm);
  r.run.trace = o.trace;
  r.run.output = o.output;
  r.run.ranks = ranks;
  r.run.nodes = o.nodes;
  r.run.cores = o.cores;
  r.run.first = first;
  r.run.read_ms = read_ms;
  r.run.max_rss_mib = max_rss_mib(comm);
  if (rank == 0 && !o.output.empty())
    partition::write_assignment(o.output, r.result.assignment, r.result.hashes);
  return r;
}

}  // namespace tgraph::mpi
