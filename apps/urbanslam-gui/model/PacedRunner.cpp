#include "PacedRunner.h"

#include <algorithm>
#include <chrono>

namespace urbanslam::gui {

PacedRunner::PacedRunner(std::function<Step()> step) : step_(std::move(step)) { thread_ = std::thread([this] { loop(); }); }

PacedRunner::~PacedRunner() { stop(); }

void PacedRunner::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void PacedRunner::play() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = true;
    // Play overrides a pending single step: otherwise a play arriving while that step runs is
    // undone when the step reports its unit done, and the runner pauses for good.
    unit_request_ = false;
  }
  wake_.notify_all();
}

void PacedRunner::pause() {
  std::lock_guard<std::mutex> lock(mutex_);
  running_ = false;
  unit_request_ = false;
}

void PacedRunner::stepUnit() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    unit_request_ = true;
    running_ = true;
  }
  wake_.notify_all();
}

void PacedRunner::setSpeed(double factor) {
  std::lock_guard<std::mutex> lock(mutex_);
  speed_ = factor;
}

bool PacedRunner::unitRequested() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return unit_request_;
}

void PacedRunner::loop() {
  using clock = std::chrono::steady_clock;
  clock::time_point wall0 = clock::now();
  double log0 = -1;
  bool was_running = false;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || (running_ && !finished_); });
      if (stop_) return;
    }
    if (!was_running) {  // resumed: pace from here
      wall0 = clock::now();
      log0 = -1;
    }
    const Step s = step_();
    double speed = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!s.more) {
        finished_ = true;
        running_ = false;
      } else if (s.unit_done && unit_request_) {
        unit_request_ = false;
        running_ = false;
      }
      was_running = running_;
      speed = speed_;
    }
    // Real-time pacing: wait until the wall clock catches up with the log's clock, in short
    // naps so pause/stop stay responsive (a log with seconds between measurements, such as a
    // folder of images at 1 s each, must wait the whole gap, not one nap).
    if (s.more && s.paced && speed > 0) {
      if (log0 < 0) log0 = s.log_time;
      for (;;) {
        const double ahead = (s.log_time - log0) / speed - std::chrono::duration<double>(clock::now() - wall0).count();
        if (ahead <= 0 || stop_ || !running_) break;
        std::this_thread::sleep_for(std::chrono::duration<double>(std::min(ahead, 0.05)));
      }
    }
  }
}

}  // namespace urbanslam::gui
