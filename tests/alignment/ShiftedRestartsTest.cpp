// The ambiguity test by shifted restarts: it finds the other minimum of a street of one repeated
// design and none in a room, and its restarts, given up early when they cannot reach the match
// count that would count, decide as restarts run to the end do.
#include <gtest/gtest.h>

#include <cmath>

#include "alignment/SyntheticScan.h"
#include "urbanslam/alignment/Aligner.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/ShiftedRestarts.h"

namespace ua = urbanslam::alignment;
namespace uc = urbanslam::common;

namespace {

// A street 10 m wide whose facades repeat every 4 m: pillars of 1 m along both walls.
ua::test::World repeatedStreet() { return ua::test::pillaredStreetWorld(-5, 5, -60, 60); }

// The rule, run to the end: PL-ICP from the result shifted along x and y, by the first shift,
// twice, four times that...; another minimum is a converged restart that ends away from the
// result and matches min_match_ratio times its points.
bool otherMinimumRunInFull(const ua::IndexedReference& a, const ua::PointSet& b, const ua::AlignmentResult& result,
                           ua::AlignerOptions options, const ua::ShiftedRestarts& r) {
  options.method = ua::Method::PlIcp;
  options.icp.abandon_below_fraction = 0;
  const uc::Pose2& t = result.transform;
  for (double d = r.first_shift_m; d <= r.last_shift_m; d *= 2)
    for (const auto& [dx, dy] : {std::pair{d, 0.0}, std::pair{-d, 0.0}, std::pair{0.0, d}, std::pair{0.0, -d}}) {
      const ua::AlignmentResult o = ua::alignPointSets(a, b, {t.x + dx, t.y + dy, t.phi}, options);
      if (!o.converged || o.rms_residual_m > r.max_rms_m) continue;
      const uc::Pose2 e = uc::between(t, o.transform);
      if (std::hypot(e.x, e.y) >= r.same_minimum_m && o.matches >= r.min_match_ratio * result.matches) return true;
    }
  return false;
}

struct Case {
  ua::test::World world;
  uc::Pose2 from, to;
};

}  // namespace

TEST(ShiftedRestarts, FindTheStreetsOtherPeriodAndNoneInARoom) {
  ua::test::ScanSpec spec;
  spec.fov_rad = 2 * M_PI;
  spec.beams = 720;
  const Case street{repeatedStreet(), {0, 0, 0}, {0.5, 0.3, 0.04}};
  const Case room{ua::test::roomWorld(), {-3, 0, 0.2}, {-2.2, 0.4, 0.35}};
  int decided_ambiguous = 0, decided_unique = 0;
  for (const bool is_street : {true, false}) {
    const Case& c = is_street ? street : room;
    ua::test::ScanSpec sb = spec;
    sb.seed = 11;
    const ua::AlignerOptions o;
    const ua::IndexedReference a(ua::pointSetFromScan(ua::test::simulateScan(c.world, c.from, spec), o.scan));
    const ua::PointSet b = ua::pointSetFromScan(ua::test::simulateScan(c.world, c.to, sb), o.scan);
    ua::AlignerOptions pl = o;
    pl.method = ua::Method::PlIcp;
    const ua::AlignmentResult result = ua::alignPointSets(a, b, uc::between(c.from, c.to), pl);
    ASSERT_TRUE(result.converged) << result.failure_reason;
    // The scans' own ambiguity test (clearly more points elsewhere) and looser ones like the path
    // submaps' (nearly as many), as far as 6 m.
    for (const double ratio : {1.05, 0.9, 0.8}) {
      ua::ShiftedRestarts r;
      r.first_shift_m = 0.75;
      r.last_shift_m = 6;
      r.same_minimum_m = 0.5;
      r.min_match_ratio = ratio;
      const bool found = ua::findsOtherMinimum(a, b, result, pl, r);
      EXPECT_EQ(found, otherMinimumRunInFull(a, b, result, pl, r)) << (is_street ? "street" : "room") << " ratio " << ratio;
      if (ratio == 0.9) {
        // The street 4 m along itself matches nearly as many points; the room nowhere.
        EXPECT_EQ(found, is_street) << ratio;
        ++(found ? decided_ambiguous : decided_unique);
      }
      // Clearly more points than at the truth: nowhere, in either.
      if (ratio == 1.05) {
        EXPECT_FALSE(found) << (is_street ? "street" : "room");
      }
    }
  }
  EXPECT_EQ(decided_ambiguous, 1);
  EXPECT_EQ(decided_unique, 1);
}
