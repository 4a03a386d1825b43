// SPDX-License-Identifier: MIT
// Projective constraints.
#pragma once

#include <string>
#include <vector>

#include "tgraph/samples/body.hpp"

namespace tgraph::samples {

/// Fixed points: projects the constrained columns of a vector (f, dv, r, q, v) to zero.
class FixedConstraint {
 public:
  FixedConstraint(std::string name, Body* body, std::vector<Index> columns);
  /// Name, stable across steps.
  const std::string& name() const { return name_; }
  /// Constrained body.
  Body* body() const { return body_; }
  /// Constrained columns.
  const std::vector<Index>& columns() const { return columns_; }
  /// Zeroes the constrained columns of `v`.
  void project(StateVec& v) const;

 private:
  std::string name_;
  Body* body_;
  std::vector<Index> columns_;
};

}  // namespace tgraph::samples
