#pragma once
// Local SLAM's reference: the scans of the last few keyframes, placed by their current estimates
// in the frame of the newest (a local submap, as KISS-ICP and Cartographer match against), and
// the one matcher that places a scan in it: the odometry prior and the scan evidence weighed
// by their uncertainties (alignment/PriorScanMatcher.h). The prepared reference (kd-tree,
// normals, likelihood grid) is kept until a keyframe is added or the submap's keyframes move
// relative to each other (a closure), so the scans between two keyframes share it. A match
// widens its search only when the narrower one's is in doubt (match(), LocalSubmap.cpp).
#include <deque>
#include <memory>
#include <vector>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/alignment/HeadingCorrections.h"
#include "urbanslam/alignment/OdometryOutvotes.h"
#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/alignment/PriorScanMatcher.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/alignment/SeenThroughRate.h"
#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

alignment::PriorMatcherOptions priorMatcherOptions(const LocalOptions& options);

class LocalSubmap {
 public:
  explicit LocalSubmap(const LocalOptions& options);

  // The keyframe's scan joins the submap; the oldest beyond submap_keyframes leaves.
  void addKeyframe(const io::LaserScan& scan);
  size_t size() const { return sets_.size(); }
  // The scan's pose in the newest keyframe's frame, from the prior (the odometry since that
  // keyframe, with its covariance). poses: the current estimates of the submap's keyframes,
  // oldest first (size() of them). Not valid when the submap or the scan has too few points.
  // direction_reach_m: PriorMatcherOptions' (< 0: from the prior's travel).
  alignment::PriorMatchResult match(const io::LaserScan& scan, const common::Pose2& prior, const Eigen::Matrix3d& prior_cov,
                                    const std::vector<common::Pose2>& poses, double direction_reach_m = -1) const;

  // The keyframes' points, the count of keyframes added, the learnt seen-through rates and
  // heading corrections. The beams are rebuilt from the points and the prepared reference from
  // both at the next match, as a cache miss would (the same inputs give the same reference).
  // with_heading_corrections, with_outvotes: false for maps written before they were kept.
  void writeState(common::BinaryWriter& w) const;
  void readState(common::BinaryReader& r, bool with_heading_corrections = true, bool with_origins = true, bool with_outvotes = true);

 private:
  const alignment::MatchReference* reference(const std::vector<common::Pose2>& poses) const;
  alignment::PointSet points(const io::LaserScan& scan) const;

  alignment::PriorMatcherOptions matcher_;
  alignment::ScanModelOptions scan_model_;
  size_t capacity_;
  std::deque<alignment::PointSet> sets_;        // each keyframe's points in its own frame
  std::deque<alignment::BeamFreeSpace> beams_;  // the space each keyframe's beams passed through
  size_t generation_ = 0;                       // keyframes added so far
  struct Cache {
    size_t generation = static_cast<size_t>(-1);
    std::vector<common::Pose2> offsets;  // each keyframe in the newest one's frame
    std::unique_ptr<const alignment::MatchReference> reference;
  };
  mutable Cache cache_;
  // Learnt from the matches as they come (what the free-space evidence weighs: the matcher's
  // seen_through_rate); it changes what the submap matches, not the submap itself.
  mutable alignment::SeenThroughRate seen_through_{0.05}, seen_through_displaced_{0.3};
  // Learnt the same way: how much of the prior's heading window the search needs.
  mutable alignment::HeadingCorrections heading_corrections_;
  // And how often the matches outvote the odometry: where rarely, its Gaussian bounds the first match.
  mutable alignment::OdometryOutvotes outvotes_;
};

}  // namespace urbanslam::slam
