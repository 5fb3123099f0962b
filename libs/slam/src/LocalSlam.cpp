#include "urbanslam/slam/LocalSlam.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

LocalSlam::LocalSlam(const PipelineOptions& options)
    : keyframe_options_(options.keyframes),
      options_(options.local),
      motion_model_(options.motion.model),
      motion_(options.motion, options.vehicle),
      submap_(options.local) {}

bool LocalSlam::addOdometry(const io::OdometryReading& m) {
  if (motion_model_ == MotionOptions::Model::Steering) return false;
  motion_.addOdometry(m);
  return true;
}

bool LocalSlam::addDrive(const io::DriveReading& m) {
  if (motion_model_ == MotionOptions::Model::Odometry) return false;
  motion_.addDrive(m);
  return true;
}

bool LocalSlam::isKeyframe() const {
  const common::Pose2& d = motion_.increment();
  return keyframes_ == 0 || !have_scan_keyframe_ || std::hypot(d.x, d.y) >= keyframe_options_.min_translation_m ||
         std::abs(d.phi) >= keyframe_options_.min_rotation_deg * kDeg;
}

KeyframeConstraint LocalSlam::keyframeConstraint(const io::LaserScan& scan) const {
  KeyframeConstraint c;
  c.z = motion_.increment();
  c.cov = motion_.covariance();
  c.cov.diagonal() += Eigen::Vector3d(1e-8, 1e-8, 1e-10);  // no motion at all is still a valid constraint
  // Scan matching needs scans on both sides (camera-only keyframes have none).
  if (!options_.scan_matching || scan.ranges.empty() || !last_keyframe_has_scan_) return c;
  const alignment::PriorMatchResult r = matchSubmap(scan, c.z, c.cov);
  c.matched_fraction = r.valid ? r.matchedFraction() : 0.0;
  if (!r.valid) {
    c.match = KeyframeConstraint::Match::Rejected;
    return c;
  }
  c.match = KeyframeConstraint::Match::Used;
  // The posterior of the increment given the motion and the scan replaces the motion's.
  c.z = r.pose;
  c.cov = esdf::withDiagonalFloors(options_.covariance_scale * r.cov, options_.min_sigma_xy_m, options_.min_sigma_phi_deg * kDeg);
  // The search and the refinement disagreeing is doubt of another kind: added after the floors
  // (which bound the Hessian's optimism along every axis; added before them, a rank-one spread
  // would lift the diagonal past them and leave the other directions as tight as the Hessian),
  // and not scaled (the scale stands for matches sharing the submap's points, which the spread
  // does not come from).
  c.cov += r.spread;
  return c;
}

std::optional<ScanAnchor> LocalSlam::placeScan(const io::LaserScan& scan, const ScanAnchor* previous, double* matched_fraction) {
  if (!options_.scan_matching || !options_.match_every_scan || scan.ranges.empty() || !last_keyframe_has_scan_) return std::nullopt;
  if (have_anchor_ && std::abs(scan.timestamp - last_anchor_time_) < options_.match_min_interval_s) return std::nullopt;
  // Its pose in the last keyframe's frame, for the trajectory at sensor times only (the filter
  // keeps one pose per keyframe).
  Eigen::Matrix3d cov = motion_.covariance();
  cov.diagonal() += Eigen::Vector3d(1e-8, 1e-8, 1e-10);
  // The vehicle was at the newest anchor: from the odometry's pose, odometry wrong in direction
  // can have put it as far as that anchor plus the odometry's travel since (as the whole
  // increment's twice its travel does for the first scan after a keyframe, whose anchor is the
  // keyframe itself).
  double reach = -1;
  if (previous && previous->keyframe + 1 == keyframes_) {
    const common::Pose2& z = motion_.increment();
    const common::Pose2 since = common::between(previous->odom, motion_.odometryPose());
    reach = std::hypot(z.x - previous->offset.x, z.y - previous->offset.y) + std::hypot(since.x, since.y);
  }
  const alignment::PriorMatchResult r = matchSubmap(scan, motion_.increment(), cov, reach);
  if (matched_fraction) *matched_fraction = r.valid ? r.matchedFraction() : 0.0;
  if (!r.valid) return std::nullopt;
  last_anchor_time_ = scan.timestamp;
  have_anchor_ = true;
  return ScanAnchor{scan.timestamp, keyframes_ - 1, r.pose, motion_.odometryPose()};
}

void LocalSlam::keyframeAdded(const io::LaserScan& scan, const common::Pose2& z) {
  if (options_.scan_matching) {
    submap_.addKeyframe(scan);
    local_poses_.push_back(local_poses_.empty() ? common::Pose2{} : common::compose(local_poses_.back(), z));
    while (local_poses_.size() > submap_.size()) local_poses_.pop_front();
  }
  have_scan_keyframe_ = have_scan_keyframe_ || !scan.ranges.empty();
  ++keyframes_;
  last_keyframe_has_scan_ = !scan.ranges.empty();
  last_anchor_time_ = scan.timestamp;  // every keyframe anchors the trajectory
  have_anchor_ = true;
  motion_.reset();
}

void LocalSlam::correctSubmap(const SubmapEstimate& e) {
  // local_poses_[i] is keyframe first + i; the estimate's poses[j] is keyframe e_first + j.
  const size_t first = keyframes_ - local_poses_.size();
  if (e.poses.empty() || e.keyframe < first || e.keyframe >= keyframes_) return;  // the anchor left the submap
  const size_t e_first = e.keyframe + 1 - e.poses.size();
  const common::Pose2 to_local = common::compose(local_poses_[e.keyframe - first], common::inverse(e.poses.back()));
  std::vector<std::pair<size_t, common::Pose2>> moved;
  double most_m = 0;  // the farthest a submap point moves: the offset plus the turn at the grid's reach
  for (size_t k = std::max(first, e_first); k < e.keyframe; ++k) {
    const common::Pose2 p = common::compose(to_local, e.poses[k - e_first]);
    const common::Pose2& old = local_poses_[k - first];
    most_m = std::max(most_m, std::hypot(p.x - old.x, p.y - old.y) + options_.grid_radius_m * std::abs(common::wrapToPi(p.phi - old.phi)));
    moved.emplace_back(k - first, p);
  }
  // Between closures global SLAM's estimate is local SLAM's chain, up to rounding: a correction
  // that moves nothing by a micrometre would only cost a new likelihood grid. (Skipping larger
  // ones is not free: on Victoria Park, skipping those under a quarter of a grid cell took the
  // ATE from 12.9 m to 19.1 m.)
  if (most_m <= 1e-6) return;
  for (const auto& [i, p] : moved) local_poses_[i] = p;
}

alignment::PriorMatchResult LocalSlam::matchSubmap(const io::LaserScan& scan, const common::Pose2& z, const Eigen::Matrix3d& cov,
                                                   double direction_reach_m) const {
  return submap_.match(scan, z, cov, submapPoses(), direction_reach_m);
}

}  // namespace urbanslam::slam
