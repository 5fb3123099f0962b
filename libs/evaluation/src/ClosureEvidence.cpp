#include "urbanslam/evaluation/ClosureEvidence.h"

#include <cmath>

#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/FreeSpace.h"

namespace urbanslam::evaluation {

namespace {

bool samePose(const common::Pose2& p, const common::Pose2& q) {
  const common::Pose2 d = common::between(p, q);
  return std::hypot(d.x, d.y) <= kSamePoseM && std::abs(d.phi) <= kSamePoseDeg * M_PI / 180.0;
}

}  // namespace

ClosureEvidence weighClosure(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& run, const common::Pose2& reference) {
  ClosureEvidence e;
  if (a.validCount() == 0 || b.validCount() == 0) {
    e.verdict = "no_scans";
    return e;
  }
  e.run_conflict = alignment::mutualFreeSpaceConflict(a, b, run);
  e.reference_conflict = alignment::mutualFreeSpaceConflict(a, b, reference);
  alignment::AlignerOptions o;
  o.method = alignment::Method::PlIcp;  // a local refinement: where does the reference's pose lead?
  const auto r = alignment::align(a, b, reference, o);
  e.from_reference = r.transform;
  e.matched_fraction = r.matchedFraction();
  if (!r.converged)
    e.verdict = "neither";
  else if (samePose(r.transform, run))
    e.verdict = "run";
  else if (samePose(r.transform, reference))
    e.verdict = "reference";
  else
    e.verdict = "neither";
  return e;
}

}  // namespace urbanslam::evaluation
