// Local SLAM's trajectory of a log, as localization makes it, against the mapping run's local
// SLAM on the same log: with loop closing off, the run's filter holds just the chain of local
// SLAM's constraints, so both must place every keyframe and scan alike.
#include <gtest/gtest.h>

#include <cmath>

#include "TestPaths.h"
#include "urbanslam/slam/LocalTrajectory.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

TEST(LocalTrajectory, IsTheMappingRunsLocalSlamChain) {
  slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
  o.loop_closure.enabled = false;
  const std::string log = test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz");
  slam::Pipeline run(o);
  run.run(*io::openDataSource(log));

  slam::LocalTrajectory local(o);
  auto src = io::openDataSource(log);
  io::Measurement m;
  while (src->next(m)) local.add(m);

  ASSERT_EQ(local.keyframes().size(), run.keyframes().size());
  ASSERT_GT(local.keyframes().size(), 100u);
  // The keyframes: the chain of the constraints from the first.
  std::vector<common::Pose2> chain{common::Pose2{}};
  for (size_t k = 1; k < local.keyframes().size(); ++k) chain.push_back(common::compose(chain.back(), local.keyframes()[k].z));
  const common::Pose2 origin = run.keyframes()[0].pose;
  for (size_t k = 0; k < chain.size(); ++k) {
    const common::Pose2 expected = common::between(origin, run.keyframes()[k].pose);
    ASSERT_NEAR(chain[k].x, expected.x, 1e-6) << "keyframe " << k;
    ASSERT_NEAR(chain[k].y, expected.y, 1e-6) << "keyframe " << k;
    ASSERT_NEAR(common::wrapToPi(chain[k].phi - expected.phi), 0.0, 1e-7) << "keyframe " << k;
  }
  // Every scan the run placed by matching, placed alike.
  const std::vector<io::StampedPose> scans = run.scanTrajectory();
  size_t compared = 0, j = 0;
  for (const auto& s : scans) {
    while (j < local.scans().size() && local.scans()[j].timestamp < s.timestamp) ++j;
    ASSERT_LT(j, local.scans().size());
    ASSERT_EQ(local.scans()[j].timestamp, s.timestamp);
    const auto& p = local.scans()[j];
    const common::Pose2 placed = common::compose(chain[p.keyframe], p.offset);
    const common::Pose2 expected = common::between(origin, s.pose);
    EXPECT_NEAR(placed.x, expected.x, 1e-6);
    EXPECT_NEAR(placed.y, expected.y, 1e-6);
    ++compared;
  }
  EXPECT_GT(compared, local.keyframes().size());
}
