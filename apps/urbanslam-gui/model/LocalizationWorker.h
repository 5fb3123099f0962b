#pragma once
// Localizes a log in a saved map (map.usmap) on its own thread, with the same play / pause /
// step / speed controls as PipelineWorker: the map's keyframes are drawn as they were saved, and
// the vehicle's pose in them scan by scan, tracked or lost (what `urbanslam localize` computes).
// A file that holds separate maps is searched as `localize` searches it when no map is named:
// every map side by side until one finds the log's place; the first map is drawn until then,
// the one that found it from then on.
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "MapSnapshot.h"
#include "PacedRunner.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/LocalizeInMaps.h"
#include "urbanslam/slam/Localizer.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::gui {

class LocalizationWorker {
 public:
  // Loads the map and opens the log; throws common::InputError with the CLI's message on bad
  // input (a map that is not a map, a log with nothing the map's [input] accepts is found later).
  LocalizationWorker(const std::string& map_path, const std::string& log_path);
  ~LocalizationWorker();

  void play() { runner_.play(); }
  void pause() { runner_.pause(); }
  void stepScan() { runner_.stepUnit(); }  // localizes the next scan, then pauses
  // 0 = as fast as possible; otherwise log seconds per wall second (1 = real time).
  void setSpeed(double factor) { runner_.setSpeed(factor); }

  bool finished() const { return runner_.finished(); }
  std::string error() const;
  const std::string& mapPath() const { return map_path_; }
  const std::string& logPath() const { return log_path_; }

  MapSnapshot snapshot() const;
  size_t version() const;

 private:
  PacedRunner::Step step();
  void record(const slam::LocalizedScan& r, double step_ms);  // under mutex_
  void drawMap(size_t k);                                     // under mutex_: map k's keyframes

  std::string map_path_, log_path_;
  std::vector<std::unique_ptr<slam::Pipeline>> maps_;  // the file's maps, the first first; read only
  std::unique_ptr<io::DataSource> source_;
  std::vector<std::unique_ptr<slam::Localizer>> localizers_;  // one per map
  std::unique_ptr<slam::MapsLocalizer> localizer_;
  size_t drawn_ = 0;  // the map drawn

  mutable std::mutex mutex_;  // guards error_ and state_
  std::string error_;
  MapSnapshot state_;
  double first_timestamp_ = -1;
  PacedRunner runner_{[this] { return step(); }};  // last: its thread ends before the rest goes
};

}  // namespace urbanslam::gui
