#pragma once
// Local SLAM (Cartographer's split): the motion since the last keyframe from odometry or the
// steering model, the keyframe decision, and the one matcher that weighs that motion against
// the scan's fit to the local submap. It reads the map (the submap keyframes' poses) and never
// changes the filter: it hands global SLAM a constraint for each new keyframe and places the
// scans between keyframes relative to the last one.
#include <Eigen/Core>
#include <optional>

#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/LocalSubmap.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/MotionIntegrator.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

// The constraint from the last keyframe to a new one: the motion, or the posterior of a scan
// match given the motion as a prior.
struct KeyframeConstraint {
  common::Pose2 z;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  enum class Match { NotTried, Used, Rejected } match = Match::NotTried;
};

class LocalSlam {
 public:
  explicit LocalSlam(const PipelineOptions& options);

  // Motion input; false when the configured motion model ignores this kind of reading.
  bool addOdometry(const io::OdometryReading& m);
  bool addDrive(const io::DriveReading& m);
  const MotionIntegrator& motion() const { return motion_; }

  // Has the vehicle moved or turned enough since the last keyframe for this scan to be one?
  // (The first scan after camera-only keyframes starts the laser map.)
  bool isKeyframe(const Map& map) const;
  // The constraint for a new keyframe at `scan` from the last one in `map`.
  KeyframeConstraint keyframeConstraint(const io::LaserScan& scan, const Map& map) const;
  // A scan between keyframes placed by its submap match, relative to the last keyframe; none
  // when not matched (disabled, too soon after the last anchor, or no valid match).
  std::optional<ScanAnchor> placeScan(const io::LaserScan& scan, const Map& map) const;
  // `scan` became the newest keyframe: it joins the submap, and the motion starts again there.
  void keyframeAdded(const io::LaserScan& scan);

  // Motion, submap and keyframe decision state (PipelineState.cpp).
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r);

 private:
  alignment::PriorMatchResult matchSubmap(const io::LaserScan& scan, const common::Pose2& z, const Eigen::Matrix3d& cov,
                                          const Map& map) const;

  KeyframeOptions keyframe_options_;
  LocalOptions options_;
  MotionOptions::Model motion_model_;
  MotionIntegrator motion_;
  LocalSubmap submap_;
  bool have_scan_keyframe_ = false;  // camera-only logs make a keyframe of every image until a scan comes
};

}  // namespace urbanslam::slam
