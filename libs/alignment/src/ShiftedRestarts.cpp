#include "urbanslam/alignment/ShiftedRestarts.h"

#include <algorithm>
#include <cmath>

namespace urbanslam::alignment {

bool findsOtherMinimum(const IndexedReference& a, const PointSet& b, const AlignmentResult& result, AlignerOptions options,
                       const ShiftedRestarts& restarts) {
  options.method = Method::PlIcp;
  // A restart counts only when it matches min_match_ratio times the result's points: one that
  // cannot reach that share is given up once settled near the final gate, as the first
  // alignment's runs are (IcpOptions::abandon_below_fraction).
  if (!b.empty())
    options.icp.abandon_below_fraction =
        std::max(options.icp.abandon_below_fraction, restarts.min_match_ratio * result.matches / static_cast<double>(b.size()));
  const common::Pose2& t = result.transform;
  for (double d = restarts.first_shift_m; d <= restarts.last_shift_m; d *= 2) {
    for (const common::Pose2& g : {common::Pose2{t.x + d, t.y, t.phi}, common::Pose2{t.x - d, t.y, t.phi},
                                   common::Pose2{t.x, t.y + d, t.phi}, common::Pose2{t.x, t.y - d, t.phi}}) {
      const AlignmentResult other = alignPointSets(a, b, g, options);
      if (!other.converged || other.rms_residual_m > restarts.max_rms_m) continue;
      const common::Pose2 e = common::between(t, other.transform);
      if (std::hypot(e.x, e.y) < restarts.same_minimum_m) continue;  // back to the same minimum
      if (other.matches >= restarts.min_match_ratio * result.matches) return true;
    }
  }
  return false;
}

}  // namespace urbanslam::alignment
