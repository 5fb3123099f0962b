#pragma once
// A consistent copy of what the pipeline has built so far, handed from the pipeline's thread to
// the GUI. Keyframe scans are shared (immutable once made), so a snapshot costs a copy of the
// poses and small vectors, not of the map points.
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/Observer.h"

namespace urbanslam::gui {

struct KeyframeView {
  size_t index = 0;
  double timestamp = 0;
  common::Pose2 pose;
  std::shared_ptr<const std::vector<io::Point2>> points;  // scan points in the vehicle frame
  // The keyframe's camera image, when it has one. Shared, never copied: the pixel buffer is the
  // reader's (immutable), so a snapshot copies a pointer, not the frame.
  std::shared_ptr<const io::CameraImage> image;
};

// A Tree of Words proposal: the current keyframe's image shows the place of an earlier one.
struct ImageMatchView {
  size_t current = 0, matched = 0;  // keyframe indices
  double score = 0;                 // normalised score
  bool accepted = false;
  std::string fate;  // accepted | pending | alignment | gating | unconfirmed | no_scans | ...
};

struct RunStats {
  size_t scans = 0, keyframes = 0, closures_accepted = 0, closures_rejected = 0;
  double log_time_s = 0;    // log time covered so far
  double processing_s = 0;  // time spent in the pipeline
  double progress = 0;
  std::vector<double> step_ms;  // recent per-scan processing times (bounded)

  static constexpr size_t kStepHistory = 2000;
  // One processed step: its log time since the first, its cost and the input's progress.
  void addStep(double log_time, double ms, double input_progress) {
    log_time_s = log_time;
    processing_s += ms / 1000.0;
    progress = input_progress;
    if (step_ms.size() >= kStepHistory) step_ms.erase(step_ms.begin(), step_ms.begin() + kStepHistory / 2);
    step_ms.push_back(ms);
  }
};

// Localization in a saved map: the vehicle's pose at a localized scan.
struct LocalizedView {
  double timestamp = 0;
  common::Pose2 pose;
  bool tracking = false;  // else lost: the pose is dead reckoning from the last one tracked
};

struct MapSnapshot {
  size_t version = 0;  // increases with every change; the GUI redraws only on a new version
  std::vector<KeyframeView> keyframes;
  std::array<double, 9> current_covariance{};
  std::vector<slam::LoopClosureEvent> closures;
  std::vector<size_t> candidates;                     // of the current keyframe
  std::shared_ptr<const io::CameraImage> last_image;  // the latest camera frame of the log
  std::vector<ImageMatchView> image_matches;          // in the order proposed
  RunStats stats;
  bool finished = false;
  // Localizing in a saved map (LocalizationWorker): `keyframes` is the map as saved, these are
  // the localized scans that had a pose, and current_covariance is the last one's.
  bool localizing = false;
  std::vector<LocalizedView> localized;
  size_t lost_scans = 0, relocalisations = 0;
};

}  // namespace urbanslam::gui
