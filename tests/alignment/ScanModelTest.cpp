// Scan model (thesis eqs. 3.3-3.5, r_max gate) and the four-step subsampling of §3.3.2.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/alignment/Subsampling.h"

namespace ua = urbanslam::alignment;

TEST(ScanModel, RangeSigmaGrowsWithRangeOverRmax) {
  ua::ScanModelOptions o;
  o.range_sigma_m = 0.1;
  o.bearing_sigma_rad = 0.01;
  const Eigen::Matrix2d R0 = ua::rangeBearingCovariance(0.0, 40.0, o);
  const Eigen::Matrix2d R40 = ua::rangeBearingCovariance(40.0, 40.0, o);
  const Eigen::Matrix2d R20 = ua::rangeBearingCovariance(20.0, 40.0, o);
  EXPECT_NEAR(R0(0, 0), 0.01, 1e-12);
  EXPECT_NEAR(R20(0, 0), std::pow(0.1 * 1.5, 2), 1e-12);  // sigma_r (1 + r / r_max)
  EXPECT_NEAR(R40(0, 0), std::pow(0.2, 2), 1e-12);
  EXPECT_NEAR(R20(1, 1), 1e-4, 1e-15);
  EXPECT_EQ(R20(0, 1), 0.0);
}

TEST(ScanModel, CartesianCovarianceIsJacobianSandwich) {
  ua::ScanModelOptions o;
  o.range_sigma_m = 0.05;
  o.bearing_sigma_rad = 0.01;
  // Along the x axis: range noise along x, bearing noise r * sigma_alpha along y.
  const Eigen::Matrix2d C = ua::cartesianCovariance(10.0, 0.0, 50.0, o);
  EXPECT_NEAR(C(0, 0), std::pow(0.05 * 1.2, 2), 1e-12);
  EXPECT_NEAR(C(1, 1), std::pow(10.0 * 0.01, 2), 1e-12);
  EXPECT_NEAR(C(0, 1), 0.0, 1e-12);
  // Rotating the bearing rotates the ellipse; the trace is invariant.
  const Eigen::Matrix2d C2 = ua::cartesianCovariance(10.0, 0.7, 50.0, o);
  EXPECT_NEAR(C2.trace(), C.trace(), 1e-12);
  const double c = std::cos(0.7), s = std::sin(0.7);
  const Eigen::Vector2d radial(c, s);
  EXPECT_NEAR(radial.dot(C2 * radial), C(0, 0), 1e-12);
}

TEST(ScanModel, GatesDropMaxRangeNaNAndInvalid) {
  ua::ScanModelOptions o;
  o.max_range_m = 30;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> r = {5, 30, 31, nan, 0.001, 7, 8};
  const std::vector<double> a = {0, 0.1, 0.2, 0.3, 0.4, nan, 0.6};
  const std::vector<uint8_t> v = {1, 1, 1, 1, 1, 1, 0};
  const auto pts = ua::makePointSet(r, a, o, v);
  ASSERT_EQ(pts.size(), 1u);
  EXPECT_EQ(pts[0].beam, 0);
  EXPECT_NEAR(pts[0].p.x(), 5.0, 1e-12);
  EXPECT_THROW(ua::makePointSet({1, 2}, {0}, o), std::invalid_argument);
}

TEST(ScanModel, LaserScanUsesSensorPoseAndScanLimit) {
  urbanslam::io::LaserScan s;
  s.ranges = {2.0f, 2.0f, 25.0f};
  s.valid = {1, 1, 1};
  s.angle_min_rad = 0;
  s.angle_increment_rad = M_PI / 2;
  s.max_range_m = 20;  // the scan's own limit is tighter than the options' 50 m
  s.sensor_pose = {1.0, 0.0, M_PI / 2};
  const auto pts = ua::pointSetFromScan(s, ua::ScanModelOptions{}, true);
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_NEAR(pts[0].p.x(), 1.0, 1e-9);  // beam 0 (+x of the sensor) points along vehicle +y
  EXPECT_NEAR(pts[0].p.y(), 2.0, 1e-9);
  EXPECT_NEAR(pts[1].p.x(), -1.0, 1e-9);
  EXPECT_NEAR(pts[1].p.y(), 0.0, 1e-9);
  // The covariance rotates with the points: radial (range) noise is now along vehicle y.
  EXPECT_GT(pts[0].cov(1, 1), 5 * pts[0].cov(0, 0));
}

// The thesis's figure 3.6: 722 raw points -> 604 after the r_max gate -> 496 after segmentation
// and small-segment removal -> 124 after decimation towards a target of 100.
TEST(Subsampling, ReproducesThesisCounts) {
  std::vector<double> ranges, bearings;
  auto add = [&](int n, double r) {
    for (int k = 0; k < n; ++k) {
      bearings.push_back(0.5 * M_PI / 180.0 * static_cast<double>(ranges.size()));
      ranges.push_back(r);
    }
  };
  for (int k = 0; k < 27; ++k) {
    add(18 + (k < 10 ? 1 : 0), 10.0);  // wall pieces, 8.7 cm spacing: one segment each
    add(4, 5.0);                       // a small cluster 5 m nearer: too small a segment
  }
  add(118, 100.0);  // no-returns beyond r_max
  ASSERT_EQ(ranges.size(), 722u);
  ua::ScanModelOptions so;
  so.max_range_m = 1000;  // let the subsampling do step 1 itself, as in the thesis
  const auto pts = ua::makePointSet(ranges, bearings, so);
  ua::SubsamplingOptions o;
  o.max_range_m = 80;
  o.segment_gap_m = 0.5;
  o.min_segment_points = 5;
  o.target_points = 100;
  const auto s = ua::subsample(pts, o);
  EXPECT_EQ(s.count_input, 722);
  EXPECT_EQ(s.count_after_range, 604);
  EXPECT_EQ(s.count_after_segments, 496);
  EXPECT_EQ(s.decimation_step, 4);
  EXPECT_EQ(s.count_after_decimation, 124);
  EXPECT_EQ(s.points.size(), 124u);
  // The segment ids of the kept points stay in sweep order.
  for (size_t i = 1; i < s.segment.size(); ++i) EXPECT_LE(s.segment[i - 1], s.segment[i]);
}

TEST(Subsampling, NoDecimationNearTarget) {
  std::vector<double> ranges(120, 5.0), bearings(120);
  for (size_t i = 0; i < 120; ++i) bearings[i] = 0.01 * static_cast<double>(i);
  const auto pts = ua::makePointSet(ranges, bearings, ua::ScanModelOptions{});
  ua::SubsamplingOptions o;
  o.target_points = 100;
  const auto s = ua::subsample(pts, o);
  EXPECT_EQ(s.decimation_step, 1);
  EXPECT_EQ(s.count_after_decimation, 120);
  EXPECT_TRUE(ua::subsample(ua::PointSet{}, o).points.empty());
}

// An outdoor scan of tree trunks (3 returns each) is the scene, not clutter: step 3 lowers its
// minimum segment size rather than dropping nearly every point.
TEST(Subsampling, SparseSceneKeepsSmallSegments) {
  std::vector<double> ranges, bearings;
  for (int t = 0; t < 40; ++t)
    for (int k = 0; k < 3; ++k) {
      bearings.push_back(0.5 * M_PI / 180.0 * static_cast<double>(ranges.size()));
      ranges.push_back(t % 2 ? 8.0 : 12.0);  // alternate ranges: 4 m jumps split the trunks
    }
  const auto pts = ua::makePointSet(ranges, bearings, ua::ScanModelOptions{});
  ua::SubsamplingOptions o;
  o.min_segment_points = 5;
  o.target_points = 1000;
  const auto s = ua::subsample(pts, o);
  EXPECT_EQ(s.min_segment_points_used, 3);
  EXPECT_EQ(s.count_after_segments, 120);
  o.min_kept_fraction = 0;  // the thesis's rule alone removes every trunk
  EXPECT_EQ(ua::subsample(pts, o).count_after_segments, 0);
}
