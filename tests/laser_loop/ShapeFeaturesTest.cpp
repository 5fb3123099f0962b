// The shape descriptors and the descriptor distances against values worked out from the
// geometry of crafted scenes (a round room, a street between two facades), and the invariances
// the detector relies on.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "urbanslam/laser_loop/Comparisons.h"
#include "urbanslam/laser_loop/ScanFeatures.h"

using namespace urbanslam;
using namespace urbanslam::laser_loop;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kShape = kThesisFeatureCount;  // where the shape block starts

// A 360° scan with 1° beams from angle_min, range r(θ) for the beam's bearing θ (0: no return).
template <class Range>
io::LaserScan scan360(Range range, double angle_min = -M_PI) {
  io::LaserScan s;
  s.angle_min_rad = angle_min;
  s.angle_increment_rad = kDeg;
  s.max_range_m = 80;
  for (int i = 0; i < 360; ++i) {
    const double r = range(angle_min + i * kDeg);
    const bool ok = r > 0 && r < 80;
    s.ranges.push_back(static_cast<float>(ok ? r : 80));
    s.valid.push_back(ok ? 1 : 0);
  }
  return s;
}

// A street along x between facades at y = +left and y = −right (no return along the street).
io::LaserScan street(double left, double right, double heading) {
  return scan360([&](double b) {
    const double s = std::sin(b + heading);
    if (std::fabs(s) < 1e-9) return 0.0;
    return s > 0 ? left / s : right / -s;
  });
}

}  // namespace

TEST(ShapeFeatures, NamesAreDistinctAndResolve) {
  for (int i = 0; i < kFeatureCount; ++i) EXPECT_EQ(featureIndex(featureName(i)), i) << featureName(i);
  for (int k = 0; k < kComparisonCount; ++k) EXPECT_EQ(comparisonIndex(comparisonName(k)), k) << comparisonName(k);
  EXPECT_STREQ(featureName(kShape), "extent_major");
  EXPECT_STREQ(featureName(kShape + kShapeQuantiles + kRangeQuantiles - 1), "range_q95");
  EXPECT_STREQ(comparisonName(kFeatureCount), "range_quantile_l1");
}

// A round room of radius 10 m about the sensor: every range is 10, so every range quantile is 10
// and the histogram (bins of r_max / 20 = 2.5 m) has all beams in bin 4. The second moments
// about the sensor are R²/2 on both axes, so both extents are R/√2. Along any axis, |R cos θ|
// for θ uniform has its p-quantile at R sin(πp/2).
TEST(ShapeFeatures, RoundRoom) {
  const FeatureVector f = computeFeatures(scan360([](double) { return 10.0; }), FeatureParams{});
  for (int k = 0; k < kRangeQuantiles; ++k) EXPECT_DOUBLE_EQ(f[kShape + kShapeQuantiles + k], 10.0);
  for (int k = 0; k < kHistogramBins; ++k) EXPECT_NEAR(f[kShape + kShapeHistogram + k], k == 4 ? 1.0 : 0.0, 1e-12) << k;
  EXPECT_NEAR(f[kShape + kShapeExtents], 10 / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(f[kShape + kShapeExtents + 1], 10 / std::sqrt(2.0), 1e-6);
  for (int k = 0; k < kAxisQuantiles; ++k) {
    const double expected = 10 * std::sin(M_PI * 0.1 * (k + 1) / 2);
    EXPECT_NEAR(f[kShape + kShapeAlong + k], expected, 0.15) << k;  // 1° beams: the quantile is within a beam's step
    EXPECT_NEAR(f[kShape + kShapeAcross + k], expected, 0.15) << k;
  }
}

// A street 6 m to the left and 10 m to the right, seen up to r_max = 50 m. The principal axis
// is the street; across it every point lies on a facade, so each |across| quantile is 6 or 10,
// and the nearer facade is seen by the larger share of short beams (it leaves r_max later).
// Along it, no short point is farther than √(50² − 6²).
TEST(ShapeFeatures, StreetBetweenTwoFacades) {
  const FeatureVector f = computeFeatures(street(6, 10, 0), FeatureParams{});
  // Across the street the points' RMS lies between the two facades' distances; along it the
  // points reach tens of metres.
  EXPECT_GT(f[kShape + kShapeExtents + 1], 6.0);
  EXPECT_LT(f[kShape + kShapeExtents + 1], 10.0);
  EXPECT_GT(f[kShape + kShapeExtents], 1.5 * f[kShape + kShapeExtents + 1]);
  for (int k = 0; k < kAxisQuantiles; ++k) {
    const double a = f[kShape + kShapeAcross + k];
    EXPECT_TRUE(std::fabs(a - 6) < 1e-3 || std::fabs(a - 10) < 1e-3) << k << ": " << a;
    EXPECT_LE(f[kShape + kShapeAlong + k], std::sqrt(50.0 * 50 - 36) + 1e-6);
  }
  // Short beams see the 6 m facade where sin θ > 6/50 and the 10 m one where sin θ > 10/50: about
  // 51 % and 49 % of the short points, so the 10 %–40 % quantiles are on the near facade, the
  // 60 %–90 % ones on the far one.
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(f[kShape + kShapeAcross + k], 6, 1e-3) << k;
  for (int k = 5; k < kAxisQuantiles; ++k) EXPECT_NEAR(f[kShape + kShapeAcross + k], 10, 1e-3) << k;
  // The range quantiles: the 5 % one is the 19th nearest beam, 9° off the perpendicular to the
  // 6 m facade (beams 0°, ±1°, ..., ±9° from it).
  EXPECT_NEAR(f[kShape + kShapeQuantiles], 6 / std::cos(9 * kDeg), 1e-4);
  // Beams along the street (within asin(6/50) of it) see nothing: r_max, in the last bin.
  EXPECT_GT(f[kShape + kShapeHistogram + kHistogramBins - 1], 0.0);
}

// Turning the sensor by whole beams turns the same points with it: the descriptors of the street
// seen at other headings are the same (the principal axes turn with the points).
TEST(ShapeFeatures, InvariantUnderHeading) {
  const FeatureVector a = computeFeatures(street(6, 10, 0), FeatureParams{});
  for (double heading : {17 * kDeg, 90 * kDeg, 203 * kDeg}) {
    const FeatureVector b = computeFeatures(street(6, 10, heading), FeatureParams{});
    for (int i = kShape; i < kFeatureCount; ++i) EXPECT_NEAR(a[i], b[i], 1e-5 * std::max(1.0, a[i])) << featureName(i) << " at " << heading;
  }
}

// The descriptor distances worked out by hand on two small descriptors.
TEST(Comparisons, DistancesByHand) {
  FeatureVector a{}, b{};
  const int h = kShape + kShapeHistogram, q = kShape + kShapeQuantiles;
  a[h] = 0.5, a[h + 1] = 0.5;                    // b: 0.25, 0.25, 0.5
  b[h] = 0.25, b[h + 1] = 0.25, b[h + 2] = 0.5;  // |Δ| = 0.25 + 0.25 + 0.5
  for (int k = 0; k < kRangeQuantiles; ++k) a[q + k] = 1.0 + k, b[q + k] = 1.5 + k;
  a[3] = 2, b[3] = 7;
  EXPECT_DOUBLE_EQ(compare(a, b, 3), 5.0);
  EXPECT_DOUBLE_EQ(compare(a, b, kFeatureCount + static_cast<int>(Distance::RangeHistogramL1)), 1.0);
  // (0.25²/0.75) · 2 + 0.5²/0.5
  EXPECT_DOUBLE_EQ(compare(a, b, kFeatureCount + static_cast<int>(Distance::RangeHistogramChi2)), 0.0625 / 0.75 * 2 + 0.5);
  EXPECT_DOUBLE_EQ(compare(a, b, kFeatureCount + static_cast<int>(Distance::RangeQuantileL1)), 0.5 * kRangeQuantiles);
  for (int k = 0; k < kComparisonCount; ++k) EXPECT_DOUBLE_EQ(compare(a, b, k), compare(b, a, k)) << comparisonName(k);
  EXPECT_EQ(compare(a, a, kFeatureCount + 1), 0.0);
}
