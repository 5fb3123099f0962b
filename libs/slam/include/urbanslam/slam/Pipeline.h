#pragma once
// The main job: measurements in, keyframes (delayed poses with their scans) and trajectory out.
// For now the estimator is dead reckoning: each scan is placed at the odometry pose of its time.
// The ESDF and loop closures replace the estimator behind this same interface.
#include <memory>
#include <vector>

#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/slam/Observer.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

struct Keyframe {
  size_t index = 0;
  double timestamp = 0;
  common::Pose2 pose;   // current estimate
  io::LaserScan scan;   // kept so the map can be rebuilt from the current estimates
};

struct PipelineStats {
  size_t measurements = 0, scans = 0, scans_used = 0, odometry = 0, drive = 0, images = 0, gps = 0,
         reference = 0, keyframes = 0;
  double first_timestamp = 0, last_timestamp = 0;
  double wall_s = 0;             // processing time, reading included
  std::vector<double> step_ms;  // per processed scan
};

class Pipeline {
 public:
  explicit Pipeline(PipelineOptions options);
  ~Pipeline();

  void addObserver(PipelineObserver* observer);
  // Processes one measurement. Returns false when the input is exhausted.
  bool step(io::DataSource& source);
  // Runs to the end of the input, then finish().
  void run(io::DataSource& source);
  // Tells observers the run is complete (call once after the last step()).
  void finish();

  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  // Estimated pose at every odometry (or drive) reading's time.
  const std::vector<io::StampedPose>& odometryTrajectory() const { return odometry_trajectory_; }
  // The log's reference trajectory, when it has one (e.g. a corrected CARMEN log).
  const std::vector<io::StampedPose>& referenceTrajectory() const { return reference_; }
  const PipelineStats& stats() const { return stats_; }
  const PipelineOptions& options() const { return options_; }

  std::vector<io::PosedScan> posedKeyframes() const;

 private:
  bool stepOnce(io::DataSource& source);
  void onScan(io::LaserScan scan, double progress);
  void onOdometry(const io::OdometryReading& m);
  void onDrive(const io::DriveReading& m);
  bool acceptLabel(const std::string& label) const;
  void applyRangeLimits(io::LaserScan& scan) const;

  PipelineOptions options_;
  std::vector<PipelineObserver*> observers_;
  std::vector<Keyframe> keyframes_;
  std::vector<io::StampedPose> odometry_trajectory_, reference_;
  std::vector<std::string> labels_;
  PipelineStats stats_;

  // Dead reckoning state.
  bool have_odom_ = false;
  common::Pose2 odom_;            // latest odometry pose
  bool have_drive_ = false;
  io::DriveReading last_drive_;
  bool have_first_ts_ = false;
};

}  // namespace urbanslam::slam
