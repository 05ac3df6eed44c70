// The processes of one rsibr run. Started by an MPI launcher (mpirun, mpiexec, srun) and built with
// MPI, a run is the ranks of MPI_COMM_WORLD; otherwise it is one rank and nothing here talks to
// another process. Only `bake` (its texels split over the ranks) and `batch` (its jobs spread over
// them) use more than one rank; every other verb refuses to run under a launcher with more than one.
//
// main() makes the one Session of the process (MPI_Init_thread on construction, MPI_Finalize on
// destruction); Session::current() is that session, or a single rank while a ScopedSingleRank is
// alive (a batch runs each job as a one-process run).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rsibr::cluster {

class Session {
 public:
  Session();  // joins the MPI job when launched by one (see launched_by_mpi), else a single rank
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  static const Session& current();
  static bool built_with_mpi();
  // True when the environment of this process names an MPI job (OMPI_COMM_WORLD_SIZE, PMI_SIZE,
  // PMIX_RANK): a plain `rsibr` never initialises MPI, so it starts as fast and leaks nothing.
  static bool launched_by_mpi();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }
  // Ranks on this machine (MPI_COMM_TYPE_SHARED), for the default thread count.
  int local_size() const { return local_size_; }
  // Worker threads a rank uses by default: this machine's cores shared among its ranks, at least 1.
  int default_threads() const;

  // Every rank's bytes at the root, in rank order (root: size() buffers; other ranks: none). Any
  // length: sent in pieces below MPI's 2^31 count limit. Collective: every rank calls it.
  std::vector<std::vector<std::uint8_t>> gather(const std::vector<std::uint8_t>& mine) const;
  // Collective: true on every rank when `ok` is true on every rank.
  bool all(bool ok) const;

 private:
  friend class ScopedSingleRank;
  struct Single {};
  explicit Session(Single);
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool joined_ = false;  // MPI initialised by this session
};

// While alive, Session::current() is a single rank (a batch job runs as a one-process run).
class ScopedSingleRank {
 public:
  ScopedSingleRank();
  ~ScopedSingleRank();
  ScopedSingleRank(const ScopedSingleRank&) = delete;
  ScopedSingleRank& operator=(const ScopedSingleRank&) = delete;

 private:
  const Session* previous_;
};

namespace detail {
void register_main_session(const Session* s);  // by the constructor and destructor of main's session
int launcher_size();                           // ranks the launcher's environment names, 1 if none
}  // namespace detail

// Bytes of a text, and back (for gathering messages and JSON).
std::vector<std::uint8_t> bytes_of(const std::string& text);
std::string text_of(const std::vector<std::uint8_t>& bytes);

}  // namespace rsibr::cluster
