// SPDX-License-Identifier: MIT
// The verbs of `tgraph-mpi`, each in its own cmd_<verb>.cpp: they parse flags and call
// tgraph::mpi. Every rank parses the same command line.
#pragma once

// smpicxx (an SMPI build) force-includes smpi_helpers.h, whose function-like macro exit(x)
// would rename CLI11's App::exit; the program never calls exit() itself.
#ifdef TGRAPH_SMPI
#undef exit
#endif
#include <CLI/CLI.hpp>

namespace tgraph::mpi_app {

/// `tgraph-mpi replay T.tgt [A.tga] --threads-per-rank T [--check] [--json]`.
void add_replay_verb(CLI::App& app);
/// `tgraph-mpi partition T.tgt --method ptscotch ... -o A.tga`.
void add_partition_verb(CLI::App& app);
/// `tgraph-mpi calibrate [-o F]`: MPI latency and bandwidth into the calibration file.
void add_calibrate_verb(CLI::App& app);

}  // namespace tgraph::mpi_app
