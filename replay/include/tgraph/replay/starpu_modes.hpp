// SPDX-License-Identifier: MIT
// StarPU's access mode of a task's access and the configuration of its CPU workers: the one
// mapping of tgraph's StarPU runs (replay's starpu policy and mpi's StarPU-MPI replay). Include it only where StarPU is found (the
// builds that define TGRAPH_HAVE_STARPU or TGRAPH_HAVE_STARPU_MPI).
#pragma once

#include <starpu.h>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::replay {

/// StarPU's mode for `m`. A CW access is one of a lowered group: RW (its writers in program
/// order), or with `commute` RW | COMMUTE (CW groups left with several writers per datum, no
/// per-writer temporaries, which StarPU may then run in any order, one at a time).
inline starpu_data_access_mode to_starpu(AccessMode m, bool commute = false) {
  switch (m) {
    case AccessMode::R:
      return STARPU_R;
    case AccessMode::W:
      return STARPU_W;
    case AccessMode::RW:
      return STARPU_RW;
    case AccessMode::CW:
      return commute ? static_cast<starpu_data_access_mode>(STARPU_RW | STARPU_COMMUTE)
                     : STARPU_RW;
  }
  return STARPU_RW;
}

/// `conf` initialised for `ncpus` CPU workers only: no CUDA, OpenCL, MIC or MPI master-slave
/// workers, no performance-model or bus calibration, the signals (SIGINT, SIGSEGV) left to the
/// application, and these values over StarPU's environment variables (STARPU_NCPU etc.).
inline void cpu_only_conf(starpu_conf& conf, unsigned ncpus) {
  starpu_conf_init(&conf);
  conf.precedence_over_environment_variables = 1;
  conf.ncpus = static_cast<int>(ncpus);
  conf.ncuda = conf.nopencl = conf.nmic = conf.nmpi_ms = 0;  // CPU workers only
  conf.calibrate = conf.bus_calibrate = 0;
  conf.catch_signals = 0;
}

}  // namespace tgraph::replay
