#pragma once
// A progress bar on stderr, shown only when stderr is a terminal and not --quiet, redrawn at
// most ~10 times a second so it costs nothing on a hot loop.
#include <chrono>
#include <cstdint>
#include <string>

namespace urbanslam::common {

class ProgressBar {
 public:
  // total == 0: unknown length (shows a count instead of a bar).
  ProgressBar(std::string label, uint64_t total, bool enabled);
  ~ProgressBar();
  void update(uint64_t done, const std::string& status = {});
  void finish();
  bool enabled() const { return enabled_; }

  // True when stderr is a terminal.
  static bool stderrIsTerminal();

 private:
  void draw(uint64_t done, const std::string& status);

  std::string label_;
  uint64_t total_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace urbanslam::common
