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
  esdf::PoseChainSmoother chain;
  size_t next_keyframe = 0;
  bool fixed = false;             // no fix for the newest keyframe: it has one, or is too near the last
  common::Pose2 at, last_fix_at;  // keyframe positions in local SLAM's frame
  bool any_fix = false;
  for (size_t i = 0; i < scans.size(); ++i) {
    const LocalTrajectory::PlacedScan& p = placed[i];
    if (p.timestamp != scans[i].timestamp) throw std::logic_error("smoothLocalization: the scans differ in time");
    for (; next_keyframe <= p.keyframe; ++next_keyframe) {
      const LocalTrajectory::Step& s = trajectory.keyframes()[next_keyframe];
      chain.addPose(s.z, s.cov);
      if (next_keyframe > 0) at = common::compose(at, s.z);
      fixed = any_fix && std::hypot(at.x - last_fix_at.x, at.y - last_fix_at.y) < fix_spacing_m;
    }
    if (fixed || !scans[i].map_fix) continue;
    any_fix = true;
    last_fix_at = at;
    // The scan's fix moved to its keyframe: k = s ⊕ ⊖o, the covariance through d k / d s.
    const esdf::Vec3 s = esdf::toVec(scans[i].map_pose), back = esdf::inverse(esdf::toVec(p.offset));
    esdf::Mat3 j;
    esdf::composeJacobians(s, back, &j, nullptr);
    chain.addFix(esdf::toPose(esdf::compose(s, back)), fix_covariance_scale * j * scans[i].map_cov * j.transpose());
    fixed = true;
  }
  const std::vector<common::Pose2> keyframes = chain.smooth();
  std::vector<common::Pose2> out;
  if (keyframes.empty()) return out;
  out.reserve(scans.size());
  for (const auto& p : placed) out.push_back(common::compose(keyframes[p.keyframe], p.offset));
  return out;
}

}  // namespace urbanslam::slam
