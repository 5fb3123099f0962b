#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "TestPaths.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {
namespace {

// The shipped model and vocabulary are where every program looks for them, and a path the ini
// sets is kept.
TEST(DefaultPaths, ResolveToTheShippedFilesUnlessSet) {
  const std::string home = URBANSLAM_SOURCE_DIR;
  PipelineOptions o;
  resolveDefaultPaths(o, home);
  EXPECT_TRUE(std::filesystem::exists(o.image_loop.vocabulary)) << o.image_loop.vocabulary;
  EXPECT_EQ(std::filesystem::path(o.loop_closure.laser_model), std::filesystem::path(home) / "share/laser_loop/default.model");
  EXPECT_EQ(std::filesystem::path(o.loop_closure.laser_model_360), std::filesystem::path(home) / "share/laser_loop/default-360.model");
  EXPECT_TRUE(std::filesystem::exists(o.loop_closure.laser_model));
  EXPECT_TRUE(std::filesystem::exists(o.loop_closure.laser_model_360));
  PipelineOptions set;
  set.loop_closure.laser_model = "mine.model";
  set.image_loop.vocabulary = "mine.usvoc";
  resolveDefaultPaths(set, home);
  EXPECT_EQ(set.loop_closure.laser_model, "mine.model");
  EXPECT_EQ(set.image_loop.vocabulary, "mine.usvoc");
}

// A laser that sees all around gets the 360° model; a front laser (180°, or 270°) the general one.
TEST(DefaultPaths, TheModelFollowsTheLasersFieldOfView) {
  LoopClosureOptions lc;
  lc.laser_model = "any.model";
  lc.laser_model_360 = "all-around.model";
  auto scan = [](int beams, double increment_deg) {
    io::LaserScan s;
    s.ranges.assign(static_cast<size_t>(beams), 5.f);
    s.valid.assign(static_cast<size_t>(beams), 1);
    s.angle_min_rad = -M_PI;
    s.angle_increment_rad = increment_deg * M_PI / 180;
    return s;
  };
  EXPECT_EQ(laserModelFor(lc, scan(720, 0.5)), "all-around.model");
  EXPECT_EQ(laserModelFor(lc, scan(360, 1.0)), "all-around.model");
  EXPECT_EQ(laserModelFor(lc, scan(361, 0.5)), "any.model");
  EXPECT_EQ(laserModelFor(lc, scan(541, 0.5)), "any.model");
  EXPECT_EQ(laserModelFor(lc, io::LaserScan{}), "any.model");
  EXPECT_EQ(laserModelFor(LoopClosureOptions{}, scan(360, 1.0)), "share/laser_loop/default-360.model");
  EXPECT_EQ(laserModelFor(LoopClosureOptions{}, scan(181, 1.0)), "share/laser_loop/default.model");
}

}  // namespace
}  // namespace urbanslam::slam
