// SPDX-License-Identifier: MIT
// The list scheduler on the Standard Task Graph Set graphs of tests/data/stg.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "../stg_files.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/stg.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {
namespace {

using test::stg_files;

TEST(ListOnStg, BeatsRandomPlacementAndRespectsTheBound) {
  std::uint64_t list_total = 0, random_total = 0;
  for (const std::string& f : stg_files()) {
    const StepGraph g = read_stg(f).trace.steps[0];
    const Metrics m = compute_metrics(g);
    for (std::uint32_t k : {2u, 4u}) {
      Options o;
      o.model = model::CostModel::ideal();
      const Result list = make_strategy("list")->partition(g, k, {}, o);
      const Result rnd = make_strategy("random")->partition(g, k, {}, o);
      const std::uint64_t lm =
          model::simulate(g, list.assignment, model::CostModel::ideal()).makespan_ns;
      const std::uint64_t rm =
          model::simulate(g, rnd.assignment, model::CostModel::ideal()).makespan_ns;
      EXPECT_GE(lm, std::max<std::uint64_t>((m.work_ns + k - 1) / k, m.span_ns)) << f;
      EXPECT_LE(lm, m.work_ns) << f;
      list_total += lm;
      random_total += rm;
    }
  }
  EXPECT_LT(list_total, random_total);
}

}  // namespace
}  // namespace tgraph::partition
