// SPDX-License-Identifier: MIT
#include "tgraph/mpi/session.hpp"

#include <sys/resource.h>

#include <exception>
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

void agree_on_input(const std::function<void()>& check, MPI_Comm comm) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  std::exception_ptr error;
  try {
    check();
  } catch (...) {
    error = std::current_exception();
  }
  int failing = error ? rank : ranks;
  MPI_Allreduce(MPI_IN_PLACE, &failing, 1, MPI_INT, MPI_MIN, comm);
  if (failing == rank) std::rethrow_exception(error);
  if (failing < ranks)  // never sent: MPI_Abort from rank `failing` ends this wait
    MPI_Recv(nullptr, 0, MPI_BYTE, failing, 0, comm, MPI_STATUS_IGNORE);
}

double max_rss_mib(MPI_Comm comm) {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  double mib = static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux: kilobytes
  MPI_Allreduce(MPI_IN_PLACE, &mib, 1, MPI_DOUBLE, MPI_MAX, comm);
  return mib;
}

}  // namespace tgraph::mpi
