#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "TestPaths.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {
const std::string kExcerpt = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");

struct CountingObserver : slam::PipelineObserver {
  size_t keyframes = 0, steps = 0;
  bool finished = false;
  void onKeyframe(const slam::KeyframeEvent& e) override {
    EXPECT_EQ(e.index, keyframes);
    EXPECT_NE(e.scan, nullptr);
    ++keyframes;
  }
  void onStep(const slam::StepEvent&) override { ++steps; }
  void onFinished() override { finished = true; }
};
}  // namespace

TEST(DeadReckoningPipeline, KeyframesSitAtTheOdometryOfTheirTime) {
  // Independent reference: the odometry reading the reader gives with each scan's timestamp.
  std::map<double, common::Pose2> odom_at;
  {
    auto src = io::openDataSource(kExcerpt);
    io::Measurement m;
    while (src->next(m))
      if (auto* o = std::get_if<io::OdometryReading>(&m)) odom_at[o->timestamp] = o->pose;
  }
  slam::PipelineOptions o;
  o.estimator.type = slam::EstimatorOptions::Type::DeadReckoning;
  o.local.scan_matching = false;
  o.keyframes.min_translation_m = 0.3;
  o.keyframes.min_rotation_deg = 15;
  CountingObserver obs;  // outlives the pipeline
  slam::Pipeline p(o);
  p.addObserver(&obs);
  auto src = io::openDataSource(kExcerpt);
  p.run(*src);
  EXPECT_TRUE(obs.finished);
  EXPECT_EQ(obs.steps, 80u);
  EXPECT_EQ(obs.keyframes, p.keyframes().size());
  ASSERT_GT(p.keyframes().size(), 10u);
  ASSERT_LT(p.keyframes().size(), 80u);  // the rule dropped scans taken while standing still
  for (size_t i = 0; i < p.keyframes().size(); ++i) {
    const auto& k = p.keyframes()[i];
    ASSERT_TRUE(odom_at.count(k.timestamp)) << k.timestamp;
    // Dead reckoning in the map frame: the odometry seen from the first keyframe.
    const auto expected = common::between(odom_at[p.keyframes()[0].timestamp], odom_at[k.timestamp]);
    EXPECT_NEAR(k.pose.x, expected.x, 1e-9);
    EXPECT_NEAR(common::wrapToPi(k.pose.phi - expected.phi), 0, 1e-9);
    if (i == 0) continue;
    const auto d = common::between(p.keyframes()[i - 1].pose, k.pose);
    EXPECT_TRUE(std::hypot(d.x, d.y) >= 0.3 || std::abs(d.phi) >= 15 * M_PI / 180) << "keyframe " << i;
  }
  EXPECT_EQ(p.referenceTrajectory().size(), 80u);
}

TEST(DeadReckoningPipeline, LaserLabelsSelectSensors) {
  slam::PipelineOptions o;
  o.estimator.type = slam::EstimatorOptions::Type::DeadReckoning;
  o.input.laser_labels = "RLASER, ROBOTLASER1";
  slam::Pipeline p(o);
  auto src = io::openDataSource(kExcerpt);
  p.run(*src);
  EXPECT_EQ(p.stats().scans, 80u);
  EXPECT_EQ(p.stats().scans_used, 0u);
  EXPECT_TRUE(p.keyframes().empty());
  o.input.laser_labels = "FLASER";
  slam::Pipeline q(o);
  auto src2 = io::openDataSource(kExcerpt);
  q.run(*src2);
  EXPECT_EQ(q.stats().scans_used, 80u);
}

TEST(DeadReckoningPipeline, RangeLimitsInvalidateBeams) {
  slam::PipelineOptions o;
  o.estimator.type = slam::EstimatorOptions::Type::DeadReckoning;
  o.local.scan_matching = false;
  o.keyframes.min_translation_m = 0;  // every scan a keyframe
  o.input.max_range_m = 2.0;
  slam::Pipeline p(o);
  auto src = io::openDataSource(kExcerpt);
  p.run(*src);
  size_t valid = 0;
  for (const auto& k : p.keyframes()) {
    const io::LaserScan scan = p.map().scan(k.index);
    for (size_t i = 0; i < scan.size(); ++i)
      if (scan.valid[i]) {
        ++valid;
        EXPECT_LT(scan.ranges[i], 2.0f);
      }
  }
  EXPECT_GT(valid, 100u);
}

// The Intel log writes some odometry readings out of time order; the odometry-time trajectory
// (trajectory_odometry.tum) is in time order all the same, as TUM readers expect.
TEST(DeadReckoningPipeline, OdometryTrajectoryIsInTimeOrder) {
  size_t out_of_order = 0;
  std::set<double> stamps;
  {
    auto src = io::openDataSource(kExcerpt);
    io::Measurement m;
    double last = -1e300;
    while (src->next(m))
      if (auto* o = std::get_if<io::OdometryReading>(&m)) {
        out_of_order += o->timestamp < last ? 1 : 0;
        last = o->timestamp;
        stamps.insert(o->timestamp);
      }
  }
  ASSERT_GT(out_of_order, 0u) << "the excerpt no longer holds out-of-order readings: the test would prove nothing";
  slam::PipelineOptions o;
  o.estimator.type = slam::EstimatorOptions::Type::DeadReckoning;
  o.local.scan_matching = false;
  slam::Pipeline p(o);
  auto src = io::openDataSource(kExcerpt);
  p.run(*src);
  const auto traj = p.odometryTrajectory();
  EXPECT_EQ(traj.size(), stamps.size());  // one pose per distinct timestamp
  for (size_t i = 1; i < traj.size(); ++i) ASSERT_LT(traj[i - 1].timestamp, traj[i].timestamp) << "reading " << i;
}

// The Freiburg campus log has no timestamps (all 0): the reader times scan k at k seconds and
// every odometry reading before it at the same time. The trajectory must still be a function of
// time, and at a scan's time it must be that scan's pose, not the first reading of the interval
// (a metre earlier on the campus).
TEST(DeadReckoningPipeline, ReadingsSharingAScanTimeGiveTheScanPose) {
  const auto dir = test::scratchDir("shared_stamps");
  const std::string log = (dir / "shared-stamps.log").string();
  {
    std::ofstream out(log);
    double x = 0, y = 0, th = 0;
    for (int k = 1; k <= 30; ++k) {
      const int t = 0;  // as in the campus log
      for (int r = 0; r < 6; ++r) {
        x += 0.1 * std::cos(th);
        y += 0.1 * std::sin(th);
        th += 0.02;
        out << "ODOM " << x << " " << y << " " << th << " 0.5 0.1 0 " << t << " test " << t << "\n";
      }
      out << "FLASER 180";
      for (int b = 0; b < 180; ++b) out << " " << 3.0 + 0.01 * b;
      out << " " << x << " " << y << " " << th << " " << x << " " << y << " " << th << " " << t << " test " << t << "\n";
    }
  }
  slam::PipelineOptions o;
  o.estimator.type = slam::EstimatorOptions::Type::DeadReckoning;
  o.local.scan_matching = false;
  o.keyframes.min_translation_m = 0.5;
  slam::Pipeline p(o);
  auto src = io::openDataSource(log);
  p.run(*src);
  ASSERT_GE(p.keyframes().size(), 20u);
  const auto traj = p.odometryTrajectory();
  ASSERT_EQ(traj.size(), 30u);  // 180 readings on 30 distinct stamps
  std::map<double, common::Pose2> at;
  for (size_t i = 0; i < traj.size(); ++i) {
    if (i > 0) {
      ASSERT_LT(traj[i - 1].timestamp, traj[i].timestamp);
    }
    at[traj[i].timestamp] = traj[i].pose;
  }
  for (const auto& k : p.keyframes()) {
    ASSERT_TRUE(at.count(k.timestamp)) << k.timestamp;
    EXPECT_NEAR(at[k.timestamp].x, k.pose.x, 1e-9) << k.timestamp;
    EXPECT_NEAR(at[k.timestamp].y, k.pose.y, 1e-9) << k.timestamp;
    EXPECT_NEAR(common::wrapToPi(at[k.timestamp].phi - k.pose.phi), 0, 1e-9) << k.timestamp;
  }
}
