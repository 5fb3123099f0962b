#include "urbanslam/slam/LocalizationSmoothing.h"

#include <cmath>
#include <stdexcept>

#include "urbanslam/esdf/PoseChainSmoother.h"
#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

std::vector<common::Pose2> smoothLocalization(const LocalTrajectory& trajectory, const std::vector<LocalizedScan>& scans,
                                              double fix_covariance_scale, double fix_spacing_m) {
  const auto& placed = trajectory.scans();
  if (placed.size() != scans.size())
    throw std::logic_error("smoothLocalization: " + std::to_string(placed.size()) + " scans placed by local SLAM, " +
                           std::to_string(scans.size()) + " localized");
  // One chain per stretch between relocalisations: a place search's fix starts a new one. Local
  // SLAM's chain across a lost stretch (where the map never was, and where the vehicle lost track
  // because the scans were hard to match) is not trusted to tie the stretches together: on ACES
  // it disagreed with the fixes on either side by 0.9 m, which the smoother spread over the
  // tracked poses before the loss.
  struct Segment {
    size_t first_keyframe;
    esdf::PoseChainSmoother chain;
  };
  std::vector<Segment> segments(1, Segment{0, {}});
  size_t next_keyframe = 0;
  bool fixed = false;             // no fix for the newest keyframe: it has one, or is too near the last
  common::Pose2 at, last_fix_at;  // keyframe positions in local SLAM's frame
  bool any_fix = false;
  for (size_t i = 0; i < scans.size(); ++i) {
    const LocalTrajectory::PlacedScan& p = placed[i];
    if (p.timestamp != scans[i].timestamp) throw std::logic_error("smoothLocalization: the scans differ in time");
    for (; next_keyframe <= p.keyframe; ++next_keyframe) {
      const LocalTrajectory::Step& s = trajectory.keyframes()[next_keyframe];
      segments.back().chain.addPose(s.z, s.cov);
      if (next_keyframe > 0) at = common::compose(at, s.z);
      fixed = any_fix && std::hypot(at.x - last_fix_at.x, at.y - last_fix_at.y) < fix_spacing_m;
    }
    if (scans[i].relocalised && segments.back().chain.hasFix()) {
      segments.push_back(Segment{p.keyframe, {}});
      segments.back().chain.addPose({}, Eigen::Matrix3d::Identity());
      fixed = false;
    }
    if (fixed || !scans[i].map_fix) continue;
    any_fix = true;
    last_fix_at = at;
    // The scan's fix moved to its keyframe: k = s ⊕ ⊖o, the covariance through d k / d s.
    const esdf::Vec3 s = esdf::toVec(scans[i].map_pose), back = esdf::inverse(esdf::toVec(p.offset));
    esdf::Mat3 j;
    esdf::composeJacobians(s, back, &j, nullptr);
    segments.back().chain.addFix(esdf::toPose(esdf::compose(s, back)), fix_covariance_scale * j * scans[i].map_cov * j.transpose());
    fixed = true;
  }
  if (!any_fix) return {};
  std::vector<std::vector<common::Pose2>> smoothed;
  for (const Segment& seg : segments) smoothed.push_back(seg.chain.smooth());
  std::vector<common::Pose2> out;
  out.reserve(scans.size());
  size_t k = 0;
  for (size_t i = 0; i < placed.size(); ++i) {
    const auto& p = placed[i];
    while (k + 1 < segments.size() && segments[k + 1].first_keyframe <= p.keyframe) ++k;
    const std::vector<common::Pose2>& poses = smoothed[k];
    out.push_back(poses.empty() ? scans[i].pose : common::compose(poses[p.keyframe - segments[k].first_keyframe], p.offset));
  }
  return out;
}

}  // namespace urbanslam::slam
