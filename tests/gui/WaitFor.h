#pragma once
// Polls a condition that a worker's thread makes true, up to a time limit (tests of the GUI's
// workers).
#include <chrono>
#include <thread>

namespace urbanslam::test {

template <typename Pred>
bool waitFor(Pred p, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!p()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

}  // namespace urbanslam::test
