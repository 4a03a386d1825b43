// SPDX-License-Identifier: MIT
#include "tgraph/mpi/session.hpp"

#include <stdexcept>

namespace tgraph::mpi {

Session::Session(int& argc, char**& argv) {
  int provided = MPI_THREAD_SINGLE;
#ifdef TGRAPH_SMPI
  // SimGrid's SMPI provides MPI_THREAD_SINGLE; its replay makes every MPI call from the
  // rank's main thread (mpi/src/replay.cpp).
  constexpr int kRequired = MPI_THREAD_SINGLE;
#else
  constexpr int kRequired = MPI_THREAD_MULTIPLE;
#endif
  MPI_Init_thread(&argc, &argv, kRequired, &provided);
  if (provided < kRequired) {
    MPI_Finalize();
    throw std::runtime_error("the MPI library does not provide MPI_THREAD_MULTIPLE");
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Session::~Session() { MPI_Finalize(); }

}  // namespace tgraph::mpi
