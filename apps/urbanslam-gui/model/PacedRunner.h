#pragma once
// The thread behind the GUI's workers: runs a job one step at a time with play / pause / step
// one unit (a keyframe, a scan) / speed, pacing the steps to the log's clock when a speed is
// set. The job's own state and locking stay with its owner: the step function is called without
// any of the runner's locks held.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace urbanslam::gui {

class PacedRunner {
 public:
  struct Step {
    bool more = true;        // false: the input is done (the job has finished its work)
    bool unit_done = false;  // a requested single unit is complete: pause
    bool paced = false;      // log_time is the log time the step reached (pace to it)
    double log_time = 0;
  };
  // `step` runs on the runner's thread until it returns more = false or the runner stops.
  // `unit_requested` (the job may read it through unitRequested()) is set by stepUnit().
  explicit PacedRunner(std::function<Step()> step);
  // Ends the thread (between two steps); the owner calls stop() first when its step function
  // uses members that are destroyed before the runner.
  ~PacedRunner();
  void stop();

  void play();
  void pause();
  void stepUnit();  // runs until the job reports a unit done, then pauses
  void setSpeed(double factor);  // 0 = as fast as possible; else log seconds per wall second
  bool unitRequested() const;
  bool running() const { return running_; }
  bool finished() const { return finished_; }

 private:
  void loop();

  std::function<Step()> step_;
  mutable std::mutex mutex_;  // guards the control flags
  std::condition_variable wake_;
  std::atomic<bool> running_{false}, finished_{false}, stop_{false};
  bool unit_request_ = false;
  double speed_ = 0;
  std::thread thread_;
};

}  // namespace urbanslam::gui
