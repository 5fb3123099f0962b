#pragma once
// What the two keyframe scans of a loop closure say when the reference disagrees with it.
// References such as GMapping's corrected logs are estimates too: on the Freiburg campus the
// corrected log moves the robot 0.83 m sideways in two scans. A closure counted false against
// such a reference may be what the scans support; this makes the difference visible.
#include <string>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::evaluation {

struct ClosureEvidence {
  // run: PL-ICP started at the reference's relative pose converges to the run's measurement
  // (the scans favour the run); reference: it stays at the reference's pose; neither: it ends
  // elsewhere or does not converge; no_scans: a keyframe has no scan.
  std::string verdict;
  common::Pose2 from_reference;   // where PL-ICP started at the reference's pose ended
  double matched_fraction = 0;    // share of B's points matched there
  double run_conflict = 0;        // mutual free-space conflict at the run's measurement
  double reference_conflict = 0;  // ... and at the reference's relative pose
};

// Two poses of B in A's frame count as the same within these (PL-ICP's own spread on real
// scans is centimetres and tenths of a degree).
constexpr double kSamePoseM = 0.1;
constexpr double kSamePoseDeg = 1.0;

// `run` and `reference` are poses of B's vehicle frame in A's, as loop_closures.csv stores them.
// PL-ICP runs with the aligner's default options, not the run's [loop_closure] ones: an
// independent check of the closure, not a repeat of the run's own acceptance test.
ClosureEvidence weighClosure(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& run, const common::Pose2& reference);

}  // namespace urbanslam::evaluation
