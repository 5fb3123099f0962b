#pragma once
// The vehicle's trajectory by local SLAM alone, as a mapping run's local SLAM makes it (the same
// options, the same keyframes, every scan matched against the submap of the last keyframes), in
// a frame of its own: a chain of keyframes, each with the constraint from the one before and its
// covariance, and every scan's pose relative to its keyframe. Localization uses it for the motion
// between scans: matched against the vehicle's own recent scans, it is as smooth as a mapping
// run's trajectory, where matches against a map may follow a look-alike for a while and snap
// back (smoothLocalization, LocalizationSmoothing.h).
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/InputFilter.h"
#include "urbanslam/slam/LocalSlam.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

class LocalTrajectory {
 public:
  explicit LocalTrajectory(const PipelineOptions& options);

  // Odometry and drive readings move local SLAM; the scans [input] accepts are placed.
  void add(const io::Measurement& m);

  struct Step {  // keyframe k from keyframe k - 1 (the first's is unused)
    common::Pose2 z;
    Eigen::Matrix3d cov;
  };
  struct PlacedScan {
    double timestamp;
    size_t keyframe;       // the keyframe it hangs from (itself, for a keyframe's scan)
    common::Pose2 offset;  // its pose in that keyframe's frame
    // The share of the scan local SLAM's submap match explained (0: the match failed); -1 when
    // no match was tried (the first keyframe, a scan too soon after the last one).
    double matched_fraction = -1;
  };
  const std::vector<Step>& keyframes() const { return keyframes_; }
  // Every scan [input] accepted, in order.
  const std::vector<PlacedScan>& scans() const { return scans_; }
  // The newest scan's pose in local SLAM's frame (the chain of the keyframe constraints, then
  // the scan's offset); none before the first scan.
  std::optional<io::StampedPose> newestScan() const;

 private:
  void onScan(io::LaserScan scan);

  InputFilter input_;
  LocalSlam local_;
  std::vector<Step> keyframes_;
  std::vector<PlacedScan> scans_;
  ScanAnchor last_anchor_;       // the keyframe or matched scan the vehicle was last placed at
  common::Pose2 keyframe_pose_;  // the newest keyframe's, in local SLAM's frame
};

}  // namespace urbanslam::slam
