#pragma once
// A closure of two single scans can be wrong in a way no test of those two scans finds: along a
// street of one building design, two scans from opposite lanes align about as well 1.5 m along
// the street as at the right place, and the next pair of scans repeats the same aliasing. The
// scans each visit took along its path see more of the street: a cross street, a gap between
// buildings, a parked car. So each visit's neighbourhood along its own path becomes one point set
// in its keyframe's frame (the poses within one visit are known to centimetres). The two point
// sets aligned from the closure measure it better than the two scans did (a closure 0.4 m off
// along a street comes back to within centimetres), and another alignment nearly as good within
// the gate's reach says that the street repeats itself beyond what even they can tell.
#include <cstddef>
#include <memory>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/common/Pose2.h"

namespace urbanslam::slam {

class Map;

struct PathSubmapOptions {
  double path_m = 30;      // each visit's keyframes within this much path of the closure's keyframe
  double spacing_m = 3;    // one keyframe every this much path of it
  double voxel_m = 0.3;    // one point per cell of this size
  double min_shift_m = 6;  // the restarts' first shift (the single-scan ambiguity test covers the shorter ones)
  double ambiguity_loss = 0.05;
  double near_m = 5.0;  // disagreement: of the current submap's points this near the earlier submap's
};

// The scans of keyframes [first, last] within path_m of path of `center` (one every spacing_m),
// thinned to a point per voxel, in center's vehicle frame (the keyframes' map poses).
alignment::PointSet pathSubmap(const Map& map, size_t center, size_t first, size_t last, const PathSubmapOptions& options);

struct SubmapCheck {
  bool aligned = false;       // the two submaps could be aligned (enough overlap, not degenerate)
  common::Pose2 measurement;  // the alignment of the current visit's submap onto the earlier's
  // Another alignment, min_shift_m or more away, matches nearly as many points (at least
  // 1 - ambiguity_loss of them): a street of one repeated design, as far as the submaps reach.
  bool ambiguous = false;
  // Aligned from the closure, the two submaps share under the aligner's minimum overlap of the
  // current one's points that lie near the earlier one's: the neighbourhoods are different places.
  bool disagree = false;
};

// The two visits' submaps (the current one's path up to `current`, the earlier one's around
// `earlier`, each on its own side of the halfway keyframe between them) aligned by PL-ICP from
// the closure's measurement z (pose of current in earlier's frame). They are kept for the
// ambiguity test, the costly part, which a caller runs only when nothing else refuses the
// closure: restarts from that alignment shifted along x and y by min_shift_m, twice and four
// times that, ... as far as reach_m (what the innovation gate could admit). For the restarts and
// the disagreement the earlier visit's submap reaches reach_m further along its path each way
// than path_m: the current submap shifted anywhere within reach then still lies on the earlier
// visit's scans (a stretch of street that looks like the one reach_m away is told from it only
// where the earlier submap holds both). The measurement is the alignment onto the path_m one.
class PathSubmapAlignment {
 public:
  PathSubmapAlignment(const Map& map, size_t earlier, size_t current, const common::Pose2& z, double reach_m,
                      const PathSubmapOptions& options);
  bool aligned() const { return result_.converged; }
  const common::Pose2& measurement() const { return result_.transform; }
  bool ambiguous() const;
  // The alignment failed, matching within its final gate under the aligner's minimum overlap
  // (IcpOptions::min_overlap) of the current submap's points within near_m of the earlier
  // submap's: the scans of the two neighbourhoods contradict a closure that the single scans
  // supported.
  bool disagree() const { return disagree_; }

 private:
  PathSubmapOptions options_;
  double reach_m_ = 0;
  bool disagree_ = false;
  alignment::PointSet now_;
  std::shared_ptr<const alignment::IndexedReference> before_;  // the earlier submap of path_m
  alignment::AlignmentResult result_;                          // onto it: the measurement
  std::shared_ptr<const alignment::IndexedReference> wide_;    // of path_m + reach_m (before_ when the same keyframes)
  alignment::AlignmentResult wide_result_;                     // onto it: the restarts' start, the disagreement
};

// Both steps at once.
SubmapCheck alignPathSubmaps(const Map& map, size_t earlier, size_t current, const common::Pose2& z, double reach_m,
                             const PathSubmapOptions& options);

}  // namespace urbanslam::slam
