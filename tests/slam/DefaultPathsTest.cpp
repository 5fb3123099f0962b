#include <gtest/gtest.h>

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
  PipelineOptions set;
  set.loop_closure.laser_model = "mine.model";
  set.image_loop.vocabulary = "mine.usvoc";
  resolveDefaultPaths(set, home);
  EXPECT_EQ(set.loop_closure.laser_model, "mine.model");
  EXPECT_EQ(set.image_loop.vocabulary, "mine.usvoc");
}

}  // namespace
}  // namespace urbanslam::slam
