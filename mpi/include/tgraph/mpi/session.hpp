// SPDX-License-Identifier: MIT
// One MPI session per process: initialised with MPI_THREAD_MULTIPLE (the replay's threads
// post and poll requests themselves), finalised when the object goes.
#pragma once

#include <mpi.h>

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

}  // namespace tgraph::mpi
