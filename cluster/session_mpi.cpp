// A build with MPI: the session is MPI_COMM_WORLD when a launcher started the process.
#include "cluster/session.h"

#include <mpi.h>

#include <algorithm>
#include <stdexcept>

namespace rsibr::cluster {
namespace {

// MPI counts are ints: buffers travel in pieces of at most 1 GiB.
constexpr std::uint64_t kPiece = std::uint64_t(1) << 30;
constexpr int kTagLength = 7001, kTagPiece = 7002;

}  // namespace

Session::Session() {
  if (launched_by_mpi()) {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) {
      // Only the main thread calls MPI; the worker threads (TBB) never do.
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
      joined_ = true;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    MPI_Comm local;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
    MPI_Comm_size(local, &local_size_);
    MPI_Comm_free(&local);
  }
  detail::register_main_session(this);
}

Session::~Session() {
  detail::register_main_session(nullptr);
  if (joined_) MPI_Finalize();
}

bool Session::built_with_mpi() { return true; }

std::vector<std::vector<std::uint8_t>> Session::gather(const std::vector<std::uint8_t>& mine) const {
  if (size_ == 1) return {mine};
  if (rank_ != 0) {
    const std::uint64_t n = mine.size();
    MPI_Send(&n, 1, MPI_UINT64_T, 0, kTagLength, MPI_COMM_WORLD);
    for (std::uint64_t at = 0; at < n; at += kPiece)
      MPI_Send(mine.data() + at, int(std::min(kPiece, n - at)), MPI_BYTE, 0, kTagPiece, MPI_COMM_WORLD);
    return {};
  }
  std::vector<std::vector<std::uint8_t>> all(static_cast<std::size_t>(size_));
  all[0] = mine;
  for (int r = 1; r < size_; ++r) {
    std::uint64_t n = 0;
    MPI_Recv(&n, 1, MPI_UINT64_T, r, kTagLength, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    all[std::size_t(r)].resize(n);
    for (std::uint64_t at = 0; at < n; at += kPiece)
      MPI_Recv(all[std::size_t(r)].data() + at, int(std::min(kPiece, n - at)), MPI_BYTE, r, kTagPiece, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
  }
  return all;
}

bool Session::all(bool ok) const {
  if (size_ == 1) return ok;
  int mine = ok ? 1 : 0, every = 0;
  MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return every == 1;
}

}  // namespace rsibr::cluster
