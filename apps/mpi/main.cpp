// SPDX-License-Identifier: MIT
// `tgraph-mpi`: the verbs that run across MPI ranks (started by mpirun). Exit 0 ok, 1 failure
// of the work, 2 bad usage or bad input (one line on stderr, from rank 0 only).
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/mpi/session.hpp"
#include "tgraph/version.hpp"
#include "../option_words.hpp"
#include "verbs.hpp"

int main(int argc, char** argv) {
  using namespace tgraph::mpi_app;
  CLI::App app{"tgraph-mpi: replay and partition task graphs across MPI ranks (run under mpirun)"};
  app.set_version_flag("--version", "tgraph-mpi " + std::string(tgraph::kVersionString));
  app.require_subcommand(1);
  add_replay_verb(app);
  add_partition_verb(app);
  add_calibrate_verb(app);
  try {
    tgraph::mpi::Session session(argc, argv);
    try {
      app.parse(argc, argv);
    } catch (const CLI::Success& e) {  // --help, --version
      return session.rank() == 0 ? app.exit(e) : 0;
    } catch (const CLI::ParseError& e) {
      // Every rank parsed the same command line and failed the same way: rank 0 says so
      // once, and the ranks end together (no collective is pending).
      if (session.rank() == 0) std::cerr << "tgraph-mpi: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      const bool bad_input = dynamic_cast<const tgraph::Error*>(&e) != nullptr;
      const bool no_memory = dynamic_cast<const std::bad_alloc*>(&e) != nullptr;
      std::cerr << "tgraph-mpi: rank " << session.rank() << ": "
                << (no_memory ? "out of memory" : tgraph::app::error_line(e)) << "\n";
      // The other ranks may be blocked in a collective: end the whole job.
      MPI_Abort(MPI_COMM_WORLD, bad_input ? 2 : 1);
      return bad_input ? 2 : 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "tgraph-mpi: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
