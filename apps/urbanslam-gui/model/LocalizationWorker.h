#pragma once
// Localizes a log in a saved map (map.usmap) on its own thread, with the same play / pause /
// step / speed controls as PipelineWorker: the map's keyframes are drawn as they were saved, and
// the vehicle's pose in them scan by scan, tracked or lost (what `urbanslam localize` computes).
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "MapSnapshot.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::gui {

class LocalizationWorker {
 public:
  // Loads the map and opens the log; throws common::InputError with the CLI's message on bad
  // input (a map that is not a map, a log with nothing the map's [input] accepts is found later).
  LocalizationWorker(const std::string& map_path, const std::string& log_path);
  ~LocalizationWorker();

  void play();
  void pause();
  void stepScan();  // localizes the next scan, then pauses
  // 0 = as fast as possible; otherwise log seconds per wall second (1 = real time).
  void setSpeed(double factor);

  bool finished() const { return finished_; }
  std::string error() const;
  const std::string& mapPath() const { return map_path_; }
  const std::string& logPath() const { return log_path_; }

  MapSnapshot snapshot() const;
  size_t version() const;

 private:
  void loop();
  void record(const slam::LocalizedScan& r, double step_ms);  // under mutex_

  std::string map_path_, log_path_;
  std::unique_ptr<slam::Pipeline> map_;  // the loaded map; read only
  std::unique_ptr<io::DataSource> source_;
  std::unique_ptr<slam::Localizer> localizer_;

  mutable std::mutex mutex_;  // guards the control flags and state_
  std::condition_variable wake_;
  std::atomic<bool> running_{false}, finished_{false}, stop_{false};
  bool step_request_ = false;
  double speed_ = 0;
  std::string error_;
  MapSnapshot state_;
  double first_timestamp_ = -1;
  std::thread thread_;
};

}  // namespace urbanslam::gui
