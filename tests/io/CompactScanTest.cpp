#include "urbanslam/io/CompactScan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace urbanslam;

namespace {

io::LaserScan makeScan(double max_range_m, size_t beams) {
  io::LaserScan s;
  s.timestamp = 1234.5678;
  s.label = "FLASER";
  s.angle_min_rad = -M_PI / 2;
  s.angle_increment_rad = M_PI / static_cast<double>(beams - 1);
  s.max_range_m = max_range_m;
  s.sensor_pose = {0.1, -0.2, 0.03};
  s.ranges.resize(beams);
  s.valid.resize(beams);
  for (size_t i = 0; i < beams; ++i) {
    s.ranges[i] = static_cast<float>(0.05 + std::fmod(0.7371 * static_cast<double>(i * i), max_range_m - 0.1));
    s.valid[i] = i % 7 != 3;
  }
  return s;
}

}  // namespace

TEST(CompactScan, RoundTripWithinHalfAStep) {
  const io::LaserScan s = makeScan(80.0, 361);
  const io::CompactScan c(s);
  float longest = 0, longest_invalid = 0;
  for (size_t i = 0; i < s.size(); ++i)
    (s.valid[i] ? longest : longest_invalid) = std::max(s.valid[i] ? longest : longest_invalid, s.ranges[i]);
  EXPECT_NEAR(c.stepM(), longest / 65533.0, 1e-12);
  const io::LaserScan back = c.expand();
  ASSERT_EQ(back.size(), s.size());
  EXPECT_EQ(back.timestamp, s.timestamp);
  EXPECT_EQ(back.label, s.label);
  EXPECT_EQ(back.angle_min_rad, s.angle_min_rad);
  EXPECT_EQ(back.angle_increment_rad, s.angle_increment_rad);
  EXPECT_EQ(back.max_range_m, s.max_range_m);
  EXPECT_EQ(back.sensor_pose.x, s.sensor_pose.x);
  EXPECT_EQ(back.sensor_pose.phi, s.sensor_pose.phi);
  for (size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(back.valid[i], s.valid[i]) << "beam " << i;
    // Invalid beams keep their ranges too (the free-space test reads them); those beyond the
    // reach of the valid ones come back as the longest of them.
    if (s.ranges[i] > longest + c.stepM())
      EXPECT_EQ(back.ranges[i], longest_invalid) << "beam " << i;
    else
      EXPECT_NEAR(back.ranges[i], s.ranges[i], c.stepM() / 2 + 1e-5) << "beam " << i;
  }
  // Its valid beams are counted from the flags alone, as the expanded scan counts them.
  EXPECT_EQ(c.validCount(), s.validCount());
  EXPECT_EQ(c.validCount(), back.validCount());
  // Compacting the expanded scan again gives it back exactly (a map written and read back).
  const io::LaserScan again = io::CompactScan(back).expand();
  for (size_t i = 0; i < s.size(); ++i) EXPECT_EQ(again.ranges[i], back.ranges[i]) << "beam " << i;
}

// A CARMEN log: centimetres, no-returns at the scanner's 81.91 m. The ranges come back as the
// very floats read (so a run does not depend on whether a scan was kept compact), the
// no-returns still at the maximum.
TEST(CompactScan, CentimetreLogComesBackExactly) {
  io::LaserScan s = makeScan(81.91, 361);
  for (size_t i = 0; i < s.size(); ++i) {
    s.valid[i] = i % 11 != 0;
    s.ranges[i] = s.valid[i] ? static_cast<float>(std::round(100.0 * std::fmod(0.37 * static_cast<double>(i), 60.0)) / 100.0) : 81.91f;
  }
  const io::CompactScan c(s);
  EXPECT_DOUBLE_EQ(c.stepM(), 0.001);
  const io::LaserScan back = c.expand();
  for (size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(back.ranges[i], s.ranges[i]) << "beam " << i;
    EXPECT_EQ(back.valid[i], s.valid[i]) << "beam " << i;
  }
}

TEST(CompactScan, ShortRangeScannerKeepsMillimetres) {
  const io::LaserScan s = makeScan(5.6, 682);
  const io::CompactScan c(s);
  EXPECT_DOUBLE_EQ(c.stepM(), 0.001);
  const io::LaserScan back = c.expand();
  for (size_t i = 0; i < s.size(); ++i) EXPECT_NEAR(back.ranges[i], s.ranges[i], 0.0005 + 1e-6);
}

TEST(CompactScan, LongRangesAndOddValues) {
  io::LaserScan s = makeScan(0.0, 16);  // max range unknown: the step reaches the longest valid return
  s.ranges[0] = 300.0f;
  s.valid[0] = 1;
  s.ranges[1] = std::numeric_limits<float>::quiet_NaN();
  s.valid[1] = 0;
  s.ranges[2] = std::numeric_limits<float>::infinity();
  s.valid[2] = 0;
  s.ranges[4] = 1e6f;  // an invalid reading far beyond the step's reach
  s.valid[4] = 0;
  s.ranges[5] = -1.0f;
  s.valid[5] = 0;
  const io::CompactScan c(s);
  EXPECT_NEAR(c.stepM(), 300.0 / 65533, 1e-9);
  const io::LaserScan back = c.expand();
  EXPECT_NEAR(back.ranges[0], 300.0, c.stepM() / 2);
  EXPECT_TRUE(back.valid[0]);
  EXPECT_FALSE(std::isfinite(back.ranges[1]));
  EXPECT_FALSE(back.valid[1]);
  EXPECT_FALSE(std::isfinite(back.ranges[2]));
  EXPECT_GE(back.ranges[4], 300.0f - c.stepM());  // still beyond every return
  EXPECT_FALSE(back.valid[4]);
  EXPECT_EQ(back.ranges[5], 0.0f);
  for (size_t i = 6; i < s.size(); ++i) EXPECT_NEAR(back.ranges[i], s.ranges[i], c.stepM() / 2 + 1e-5);
}

TEST(CompactScan, EmptyScan) {
  const io::CompactScan c{io::LaserScan{}};
  EXPECT_TRUE(c.empty());
  EXPECT_EQ(c.expand().size(), 0u);
  EXPECT_TRUE(io::CompactScan().empty());
}
