#pragma once
// The localized trajectory smoothed: local SLAM's chain of keyframes (LocalTrajectory) gives the
// motion between them with its covariance, and the localizer's matches against the map (and its
// place-search fixes) give the keyframes' poses in the map; a smoother over the chain
// (esdf::PoseChainSmoother) weighs both, every pose given the matches before and after it. The
// scans between keyframes keep local SLAM's offsets. Where the localizer follows a look-alike
// pose for a few scans and snaps back, the smoothed trajectory stays with local SLAM's motion;
// where local SLAM drifts, the map's matches pull it back gradually. Each stretch between
// relocalisations (a place search's fix after the pose was lost) is smoothed on its own.
//
// One fix per `fix_spacing_m` of travel (the map's keyframe spacing, [keyframes]
// min_translation_m), the first matched scan of the first keyframe span that far from the last
// fix: consecutive scans, at nearly the same place, match the same map points, so their errors
// are correlated (the reason local SLAM's covariance_scale exists); as independent fixes they
// would outweigh local SLAM many times over. Turning on the spot makes keyframes (every 10°) but
// keeps the same map points in view: a fix for each made Intel's smoothed rotations 5 % worse
// (0.233° against 0.223°), where the vehicle turns in a room whose furniture the map saw
// elsewhere. The fixes that far apart still share most of their map points: each is taken with
// its covariance times `fix_covariance_scale` (the map's [local] covariance_scale, which says the
// same of successive submap matches).
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/slam/LocalTrajectory.h"
#include "urbanslam/slam/Localizer.h"

namespace urbanslam::slam {

// The smoothed pose of each of `scans` (the localizer's results over the same log as
// `trajectory`'s, scan for scan); empty when no scan has a fix. Throws std::logic_error when the
// two do not hold the same scans.
std::vector<common::Pose2> smoothLocalization(const LocalTrajectory& trajectory, const std::vector<LocalizedScan>& scans,
                                              double fix_covariance_scale, double fix_spacing_m);

}  // namespace urbanslam::slam
