#pragma once
// Runs the pipeline on its own thread with play / pause / step-one-keyframe / speed control, so
// the window stays responsive. The GUI reads progress only through the SnapshotCollector and
// touches the pipeline itself only through withPipeline() (exports), between two steps.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "SnapshotCollector.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::gui {

class PipelineWorker {
 public:
  // Opens the log and the ini; throws common::InputError with the CLI's message on bad input.
  // `default_laser_model`: the classifier used when the ini names none ([loop_closure] laser_model);
  // `default_vocabulary`: the same for the Tree of Words vocabulary ([image_loop] vocabulary).
  PipelineWorker(const std::string& log_path, const std::string& ini_path, const std::string& default_laser_model = "",
                 const std::string& default_vocabulary = "");
  ~PipelineWorker();

  void play();
  void pause();
  // Runs until the next keyframe is made, then pauses.
  void stepKeyframe();
  // 0 = as fast as possible; otherwise log seconds per wall second (1 = real time).
  void setSpeed(double factor);

  bool running() const { return running_; }
  bool finished() const { return finished_; }
  // The error that stopped the run (bad data found mid-way), or "".
  std::string error() const;
  const std::string& logPath() const { return log_path_; }
  const std::string& iniPath() const { return ini_path_; }
  const std::string& resolvedIni() const { return resolved_ini_; }
  const std::string& inputFormat() const { return format_; }

  SnapshotCollector& collector() { return collector_; }
  void withPipeline(const std::function<void(const slam::Pipeline&)>& f);

 private:
  void loop();
  // Global SLAM may run behind on a thread of its own: paused or exporting, the map is whole.
  void waitForGlobalSlam();

  std::string log_path_, ini_path_, resolved_ini_, format_, default_laser_model_;
  std::unique_ptr<io::DataSource> source_;
  // Before the pipeline: global SLAM's thread calls the collector until the pipeline is gone.
  SnapshotCollector collector_;
  std::unique_ptr<slam::Pipeline> pipeline_;

  mutable std::mutex mutex_;  // guards the pipeline and the control flags below
  std::condition_variable wake_;
  std::atomic<bool> running_{false}, finished_{false}, stop_{false};
  bool step_request_ = false;
  double speed_ = 0;
  std::string error_;
  std::thread thread_;
};

}  // namespace urbanslam::gui
