// A build without MPI: every run is one rank.
#include "cluster/session.h"

#include <stdexcept>

namespace rsibr::cluster {

Session::Session() {
  // N copies of a serial run would each do all the work and write the same files.
  if (detail::launcher_size() > 1)
    throw std::runtime_error("started by an MPI launcher with " + std::to_string(detail::launcher_size()) +
                             " ranks, but this rsibr was built without MPI (RSIBR_MPI); run it without mpirun");
  detail::register_main_session(this);
}

Session::~Session() { detail::register_main_session(nullptr); }

bool Session::built_with_mpi() { return false; }

std::vector<std::vector<std::uint8_t>> Session::gather(const std::vector<std::uint8_t>& mine) const { return {mine}; }

bool Session::all(bool ok) const { return ok; }

}  // namespace rsibr::cluster
