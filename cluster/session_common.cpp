// What a session is on any build: the current session, the single-rank override, thread counts.
#include "cluster/session.h"

#include <algorithm>
#include <cstdlib>
#include <thread>

namespace rsibr::cluster {
namespace {

const Session*& main_session() {
  static const Session* s = nullptr;
  return s;
}
const Session*& override_session() {
  static const Session* s = nullptr;
  return s;
}

}  // namespace

bool Session::launched_by_mpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
}

Session::Session(Single) {}

const Session& Session::current() {
  static const Session single{Single{}};
  if (override_session()) return *override_session();
  if (main_session()) return *main_session();
  return single;
}

int Session::default_threads() const {
  const int cores = int(std::thread::hardware_concurrency());
  return std::max(1, (cores > 0 ? cores : 1) / std::max(1, local_size_));
}

ScopedSingleRank::ScopedSingleRank() : previous_(override_session()) {
  static const Session single{Session::Single{}};
  override_session() = &single;
}
ScopedSingleRank::~ScopedSingleRank() { override_session() = previous_; }

std::vector<std::uint8_t> bytes_of(const std::string& text) { return {text.begin(), text.end()}; }
std::string text_of(const std::vector<std::uint8_t>& bytes) { return {bytes.begin(), bytes.end()}; }

namespace detail {

void register_main_session(const Session* s) { main_session() = s; }

int launcher_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  return 1;
}

}  // namespace detail

}  // namespace rsibr::cluster
