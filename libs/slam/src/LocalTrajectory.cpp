#include "urbanslam/slam/LocalTrajectory.h"

#include "urbanslam/io/CompactScan.h"

namespace urbanslam::slam {

LocalTrajectory::LocalTrajectory(const PipelineOptions& options) : input_(options.input), local_(options) {}

void LocalTrajectory::add(const io::Measurement& m) {
  if (const auto* scan = std::get_if<io::LaserScan>(&m)) {
    if (input_.accepts(scan->label)) onScan(*scan);
  } else if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
    local_.addOdometry(*od);
  } else if (const auto* dr = std::get_if<io::DriveReading>(&m)) {
    local_.addDrive(*dr);
  }
}

void LocalTrajectory::onScan(io::LaserScan scan) {
  input_.limitRanges(scan);
  const double t = scan.timestamp;
  if (local_.isKeyframe()) {
    // As Pipeline::addKeyframe: the submap holds the scan as a map keeps it (ranges to the
    // millimetre), so that this chain is the mapping run's.
    const KeyframeConstraint c = local_.keyframeConstraint(scan);
    io::CompactScan(scan).expandInto(scan);
    const size_t k = local_.keyframes();
    if (k > 0) keyframe_pose_ = common::compose(keyframe_pose_, c.z);
    keyframes_.push_back({c.z, c.cov});
    scans_.push_back({t, k, {}, c.match == KeyframeConstraint::Match::NotTried ? -1.0 : c.matched_fraction});
    last_anchor_ = {t, k, {}, local_.motion().odometryPose()};
    local_.keyframeAdded(scan, c.z);
    return;
  }
  if (keyframes_.empty()) return;  // isKeyframe() holds for the first scan: not reached
  double matched = -1;
  if (const auto anchor = local_.placeScan(scan, &last_anchor_, &matched)) {
    last_anchor_ = *anchor;
    scans_.push_back({t, anchor->keyframe, anchor->offset, matched});
  } else {
    // Not matched: the odometry since the keyframe places it.
    scans_.push_back({t, local_.keyframes() - 1, local_.motion().increment(), matched});
  }
}

std::optional<io::StampedPose> LocalTrajectory::newestScan() const {
  if (scans_.empty()) return std::nullopt;
  return io::StampedPose{scans_.back().timestamp, common::compose(keyframe_pose_, scans_.back().offset)};
}

}  // namespace urbanslam::slam
