#pragma once
// Local SLAM (Cartographer's split): the motion since the last keyframe from odometry or the
// steering model, the keyframe decision, and the one matcher that weighs that motion against
// the scan's fit to the local submap. It works in its own frame, the chain of the constraints it
// handed on, and never reads global SLAM's estimates: it hands global SLAM a constraint for each
// new keyframe and places the scans between keyframes relative to the last one, whenever global
// SLAM gets to them.
#include <Eigen/Core>
#include <deque>
#include <optional>

#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/LocalSubmap.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/MotionIntegrator.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/SubmapCorrections.h"

namespace urbanslam::slam {

// The constraint from the last keyframe to a new one: the motion, or the posterior of a scan
// match given the motion as a prior.
struct KeyframeConstraint {
  common::Pose2 z;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  enum class Match { NotTried, Used, Rejected } match = Match::NotTried;
  double matched_fraction = 0;  // of the scan, by the submap match (when tried)
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
  bool isKeyframe() const;
  // The constraint for a new keyframe at `scan` from the last one.
  KeyframeConstraint keyframeConstraint(const io::LaserScan& scan) const;
  // A scan between keyframes placed by its submap match, relative to the last keyframe; none
  // when not matched (disabled, too soon after the last anchor, or no valid match). `previous`:
  // the map's newest anchor (the last keyframe or a scan matched since): the vehicle was there,
  // so odometry wrong in direction can only have misled it since (the search's reach).
  // `matched_fraction`: set to the share of the scan the match explained (0 when it failed), left
  // as it is when no match was tried.
  std::optional<ScanAnchor> placeScan(const io::LaserScan& scan, const ScanAnchor* previous, double* matched_fraction = nullptr);
  // Keyframes so far (the index the next one gets).
  size_t keyframes() const { return keyframes_; }
  // `scan` became the newest keyframe, `z` the constraint from the previous one that global SLAM
  // took: the scan joins the submap, and the motion starts again there.
  void keyframeAdded(const io::LaserScan& scan, const common::Pose2& z);
  // The keyframes made so far are `keyframes` in number (this state continues a session that was
  // appended to a map: Pipeline::appendSession).
  void renumber(size_t keyframes) { keyframes_ = keyframes; }
  // Global SLAM's estimate of the submap's keyframes up to `e.keyframe`: their geometry replaces
  // the chain's there, anchored at that keyframe (so the chain's frame does not move, and the
  // keyframes after it keep their constraints).
  void correctSubmap(const SubmapEstimate& e);

  // The submap keyframes' poses in local SLAM's frame, oldest first; the newest is keyframe
  // keyframes() - 1.
  std::vector<common::Pose2> submapPoses() const { return {local_poses_.begin(), local_poses_.end()}; }

  // Motion, submap and keyframe decision state (PipelineState.cpp).
  void writeState(common::BinaryWriter& w) const;
  // with_heading_corrections: false for maps written before they were kept (LocalSubmap.h).
  void readState(common::BinaryReader& r, bool with_heading_corrections = true, bool with_origins = true, bool with_outvotes = true);

 private:
  alignment::PriorMatchResult matchSubmap(const io::LaserScan& scan, const common::Pose2& z, const Eigen::Matrix3d& cov,
                                          double direction_reach_m = -1) const;

  KeyframeOptions keyframe_options_;
  LocalOptions options_;
  MotionOptions::Model motion_model_;
  MotionIntegrator motion_;
  LocalSubmap submap_;
  // The submap keyframes' poses in local SLAM's own frame: the chain of the constraints it
  // handed on, corrected by global SLAM's estimates at a fixed lag (correctSubmap), never by
  // whatever global SLAM holds at the moment: local SLAM's results do not depend on when global
  // SLAM finishes its work.
  std::deque<common::Pose2> local_poses_;
  bool have_scan_keyframe_ = false;  // camera-only logs make a keyframe of every image until a scan comes
  size_t keyframes_ = 0;
  bool last_keyframe_has_scan_ = false;
  double last_anchor_time_ = 0;  // of the newest scan with a pose (keyframe or matched scan)
  bool have_anchor_ = false;
};

}  // namespace urbanslam::slam
