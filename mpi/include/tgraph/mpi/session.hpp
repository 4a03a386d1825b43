// SPDX-License-Identifier: MIT
// One MPI session per process: initialised with MPI_THREAD_MULTIPLE (the replay's threads
// post and poll requests themselves), finalised when the object goes.
#pragma once

#include <mpi.h>

#include <functional>

namespace tgraph::mpi {

/// MPI_Init_thread(MPI_THREAD_MULTIPLE) in the constructor, MPI_Finalize in the destructor.
/// Throws std::runtime_error when the library does not provide MPI_THREAD_MULTIPLE.
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0;
  int size_ = 1;
};

/// Runs `check` (reading and checking a command's input) on every rank of `comm`, a
/// collective call. When it throws on some rank, the lowest such rank rethrows (its caller
/// prints the one line and aborts the job) and the others wait for that abort: bad input
/// gives one line, not one per rank.
void agree_on_input(const std::function<void()>& check, MPI_Comm comm);

/// The largest peak resident set of any rank of `comm`, in MiB (a collective call).
double max_rss_mib(MPI_Comm comm);

}  // namespace tgraph::mpi
