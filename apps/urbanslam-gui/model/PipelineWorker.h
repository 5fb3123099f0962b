#pragma once
// Runs the pipeline on its own thread with play / pause / step-one-keyframe / speed control, so
// the window stays responsive. The GUI reads progress only through the SnapshotCollector and
// touches the pipeline itself only through withPipeline() (exports), between two steps.
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "PacedRunner.h"
#include "SnapshotCollector.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::gui {

class PipelineWorker {
 public:
  // Opens the log and the ini; throws common::InputError with the CLI's message on bad input.
  // `home`: the project home whose shipped classifiers and vocabulary are used where the ini
  // names none (slam::resolveDefaultPaths); empty: the library's own defaults.
  PipelineWorker(const std::string& log_path, const std::string& ini_path, const std::string& home = "");
  ~PipelineWorker();

  void play() { runner_.play(); }
  void pause() { runner_.pause(); }
  // Runs until the next keyframe is made, then pauses.
  void stepKeyframe() { runner_.stepUnit(); }
  // 0 = as fast as possible; otherwise log seconds per wall second (1 = real time).
  void setSpeed(double factor) { runner_.setSpeed(factor); }

  bool running() const { return runner_.running(); }
  bool finished() const { return runner_.finished(); }
  // The error that stopped the run (bad data found mid-way), or "".
  std::string error() const;
  const std::string& logPath() const { return log_path_; }
  const std::string& iniPath() const { return ini_path_; }
  const std::string& resolvedIni() const { return resolved_ini_; }
  const std::string& inputFormat() const { return format_; }

  SnapshotCollector& collector() { return collector_; }
  void withPipeline(const std::function<void(const slam::Pipeline&)>& f);

 private:
  PacedRunner::Step step();
  // Global SLAM may run behind on a thread of its own: paused or exporting, the map is whole.
  void waitForGlobalSlam();

  std::string log_path_, ini_path_, resolved_ini_, format_;
  std::unique_ptr<io::DataSource> source_;
  // Before the pipeline: global SLAM's thread calls the collector until the pipeline is gone.
  SnapshotCollector collector_;
  std::unique_ptr<slam::Pipeline> pipeline_;

  mutable std::mutex mutex_;  // guards the pipeline and error_
  bool done_ = false;         // finish() was called
  std::string error_;
  PacedRunner runner_{[this] { return step(); }};  // last: its thread ends before the rest goes
};

}  // namespace urbanslam::gui
