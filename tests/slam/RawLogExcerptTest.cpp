// End to end on a raw benchmark log: the first 1200 scans of the Freiburg building 079 raw log
// (rawlogs/fr079-raw-excerpt.clf.gz) with the benchmark's relations between them, which are
// independent of the run (Kümmerle et al. 2009). The shipped ini, the shipped configuration.
#include <gtest/gtest.h>

#include <memory>

#include "TestPaths.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

struct ExcerptRun {
  evaluation::RelationMetrics relations;
  evaluation::RelationLoopCheck loops;
};

ExcerptRun runExcerpt(const slam::PipelineOptions& o) {
  slam::Pipeline p(o);
  auto src = io::openDataSource(test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"));
  p.run(*src);
  const auto rel = evaluation::readRelations(test::repoPath("rawlogs/fr079-raw-excerpt.relations"));
  std::vector<evaluation::LoopRow> rows;
  for (const auto& c : p.loopClosures())
    rows.push_back({static_cast<long>(c.from), static_cast<long>(c.to), c.from_time, c.to_time, c.accepted, c.measurement});
  return {evaluation::relationMetrics(p.scanTrajectory(), rel, 0.0, 1e9),
          evaluation::checkLoopsWithRelations(rows, p.odometryTrajectory(), rel, 0.0)};
}

}  // namespace

// The run's nodes against all 287 relations: a few centimetres (0.027 m when measured), where
// the odometry alone is a metre off; every closure that a relation can check agrees with it.
TEST(RawLogExcerpt, RelationErrorAndClosuresAgainstTheBenchmarkRelations) {
  const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
  const ExcerptRun run = runExcerpt(o);
  EXPECT_EQ(run.relations.used, 287u);
  EXPECT_EQ(run.relations.skipped, 0u);
  EXPECT_LT(run.relations.abs_trans_m.mean, 0.04);
  EXPECT_LT(run.relations.abs_rot_deg.mean, 0.5);
  EXPECT_GE(run.loops.accepted, 10u);
  EXPECT_GE(run.loops.checked, 10u);
  EXPECT_EQ(run.loops.contradicted, 0u);

  slam::PipelineOptions odometry = o;
  odometry.local.scan_matching = false;
  odometry.loop_closure.enabled = false;
  EXPECT_GT(runExcerpt(odometry).relations.abs_trans_m.mean, 0.5);
}
