// A progress bar on stderr that appears only when stderr is a terminal (never in CI logs or
// pipes). Thread-safe: update() may be called from worker threads; it redraws at most ~10 times a
// second. Finished (line cleared) by done() or the destructor.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace rsibr {

class Progress {
 public:
  explicit Progress(std::string label, bool enabled = stderr_is_terminal());
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(double fraction);  // 0..1
  void done();

  static bool stderr_is_terminal();

 private:
  std::string label_;
  bool enabled_;
  bool finished_ = false;
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace rsibr
