// rsibr: reflection-space image-based rendering from photographed spheres and computed maps.
#include "cli/command_line.h"
#include "cluster/session.h"

#include <exception>
#include <iostream>
#include <memory>

int main(int argc, char** argv) {
  // The process's session: the MPI job's ranks under mpirun, otherwise one rank (cluster/session.h).
  std::unique_ptr<rsibr::cluster::Session> session;
  try {
    session = std::make_unique<rsibr::cluster::Session>();
  } catch (const std::exception& e) {
    std::cerr << "rsibr: error: " << e.what() << "\n";
    return 2;
  }
  return rsibr::cli::run_command_line({argv + 1, argv + argc}).exit_code;
}
