// SPDX-License-Identifier: MIT
// Transitional: the lowering of cumulative writes is libgraph's (tgraph/graph/lowering.hpp, a
// graph transformation). Delete this header once replay/src/program_workload.cpp includes
// that one.
#pragma once

#include "tgraph/graph/lowering.hpp"
