#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "TestPaths.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/evaluation/Evaluation.h"

using namespace urbanslam;

namespace {
// A circle driven at varying speed (so that a time shift changes the relative motions).
std::vector<io::StampedPose> circle(double offset_t = 0) {
  std::vector<io::StampedPose> t;
  double a = 0;
  for (int i = 0; i < 200; ++i) {
    a += 0.03 + 0.02 * std::sin(i * 0.3);
    t.push_back({offset_t + i * 0.1, {5 * std::cos(a), 5 * std::sin(a), a + M_PI / 2}});
  }
  return t;
}
}  // namespace

// Relation metric by hand: a trajectory with a known constant error in each relation.
TEST(Evaluation, RelationMetricMatchesHandComputedErrors) {
  const auto traj = circle();
  std::vector<evaluation::Relation> rel;
  for (int i = 0; i + 10 < 200; i += 10) {
    const auto expected = common::between(traj[static_cast<size_t>(i)].pose, traj[static_cast<size_t>(i + 10)].pose);
    // Expected perturbed on the left by d = (0.1 m, 0, 2°): error = between ⋅ (d ⋅ between)^-1 = d^-1.
    rel.push_back({traj[static_cast<size_t>(i)].timestamp, traj[static_cast<size_t>(i + 10)].timestamp,
                   common::compose({0.1, 0, 2 * M_PI / 180}, expected)});
  }
  const auto m = evaluation::relationMetrics(traj, rel, 0);
  ASSERT_EQ(m.used, rel.size());
  EXPECT_NEAR(m.abs_rot_deg.mean, 2.0, 1e-9);
  EXPECT_NEAR(m.abs_rot_deg.std, 0.0, 1e-9);
  // |d^-1| translation: 0.1 m.
  EXPECT_NEAR(m.abs_trans_m.mean, 0.1, 1e-9);
  EXPECT_NEAR(m.sqr_trans_m2.mean, 0.01, 1e-9);
  EXPECT_NEAR(m.sqr_rot_deg2.mean, 4.0, 1e-9);
}

// Nodes bridged along a dense trajectory, against poses computed here by hand: nodes that are
// the dense poses (every 20th of a circle) give the circle back where linear interpolation cuts
// its chords; nodes moved rigidly give the moved circle; one node shifted by a world offset
// carries that offset into its neighbourhood, linearly in time down to zero at the next node.
TEST(Evaluation, NodesAreBridgedAlongTheDenseTrajectory) {
  const auto dense = circle();
  std::vector<io::StampedPose> nodes;
  for (size_t i = 0; i < dense.size(); i += 20) nodes.push_back(dense[i]);
  auto bridged = evaluation::bridgeNodes(nodes, dense);
  ASSERT_EQ(bridged.size(), 181u);  // 0 .. 18.0 s at every dense time
  double worst_bridged = 0, worst_linear = 0;
  for (size_t i = 0; i < bridged.size(); ++i) {
    EXPECT_DOUBLE_EQ(bridged[i].timestamp, dense[i].timestamp);
    worst_bridged = std::max(worst_bridged, std::hypot(bridged[i].pose.x - dense[i].pose.x, bridged[i].pose.y - dense[i].pose.y));
    common::Pose2 lin;
    ASSERT_TRUE(evaluation::interpolatePose(nodes, dense[i].timestamp, 10.0, lin));
    worst_linear = std::max(worst_linear, std::hypot(lin.x - dense[i].pose.x, lin.y - dense[i].pose.y));
  }
  EXPECT_LT(worst_bridged, 1e-9);
  EXPECT_GT(worst_linear, 0.05);  // the chord of 20 steps on a 5 m circle sags by centimetres

  const common::Pose2 frame{3.0, -2.0, 0.7};
  auto moved = nodes;
  for (auto& n : moved) n.pose = common::compose(frame, n.pose);
  std::reverse(moved.begin(), moved.end());  // any time order
  bridged = evaluation::bridgeNodes(moved, dense);
  for (size_t i = 0; i < bridged.size(); ++i) {
    const common::Pose2 want = common::compose(frame, dense[i].pose);
    EXPECT_NEAR(bridged[i].pose.x, want.x, 1e-9);
    EXPECT_NEAR(bridged[i].pose.y, want.y, 1e-9);
    EXPECT_NEAR(common::wrapToPi(bridged[i].pose.phi - want.phi), 0.0, 1e-9);
  }

  auto shifted = nodes;
  shifted[3].pose.x += 0.4;  // the node at 6.0 s; its neighbours at 4.0 s and 8.0 s stay
  bridged = evaluation::bridgeNodes(shifted, dense);
  for (size_t i = 40; i <= 80; ++i) {
    const double t = dense[i].timestamp, expect_dx = 0.4 * (1.0 - std::abs(t - 6.0) / 2.0);
    EXPECT_NEAR(bridged[i].pose.x - dense[i].pose.x, expect_dx, 1e-9) << "t " << t;
    EXPECT_NEAR(bridged[i].pose.y, dense[i].pose.y, 1e-9) << "t " << t;
  }
}

TEST(Evaluation, TimeOffsetIsRecoveredFromTheReference) {
  const auto ref = circle();
  std::vector<evaluation::Relation> rel;
  const double base = 976052896.8;
  for (int i = 0; i + 5 < 200; i += 3)
    rel.push_back({base + ref[static_cast<size_t>(i)].timestamp, base + ref[static_cast<size_t>(i + 5)].timestamp,
                   common::between(ref[static_cast<size_t>(i)].pose, ref[static_cast<size_t>(i + 5)].pose)});
  EXPECT_NEAR(evaluation::findRelationTimeOffset(ref, rel), base, 1e-3);
  // Relations already in the trajectory's time base need no offset.
  std::vector<evaluation::Relation> same_base = rel;
  for (auto& r : same_base) {
    r.t1 -= base;
    r.t2 -= base;
  }
  EXPECT_EQ(evaluation::findRelationTimeOffset(ref, same_base), 0.0);
}

// The breakdown puts each relation in the class its times give it among the scans, and the
// classes' shares add up to the relation metric's mean. Scans every 2 s; the relations are
// perturbed by 0.1 m (both ends at scans), 0.2 m (inside one interval) and 0.4 m (the rest).
TEST(Evaluation, RelationsAreSplitByWhereTheyFallAmongTheScans) {
  const auto traj = circle();
  const double base = 1000.0;  // the relations' time base (offset) is applied to the scans too
  std::vector<double> scans;
  for (size_t i = 0; i < traj.size(); i += 20) scans.push_back(traj[i].timestamp);
  std::vector<evaluation::Relation> rel;
  const auto add = [&](size_t i, size_t j, double d) {
    rel.push_back(
        {base + traj[i].timestamp, base + traj[j].timestamp, common::compose({d, 0, 0}, common::between(traj[i].pose, traj[j].pose))});
  };
  add(20, 40, 0.1);    // scans at 2 s and 4 s
  add(60, 100, 0.1);   // 6 s and 10 s, scans in between do not matter
  add(23, 35, 0.2);    // 2.3-3.5 s: inside the 2-4 s interval
  add(121, 129, 0.2);  // 12.1-12.9 s
  add(25, 45, 0.4);    // a scan (4 s) between the two ends
  add(30, 40, 0.4);    // one end inside an interval, the other at its scan
  add(5, 195, 0.4);    // 19.5 s: after the last scan (18 s), not inside an interval
  add(195, 199, 0.4);
  rel.push_back({base + 50.0, base + 51.0, {}});  // outside the trajectory: skipped, not counted
  const auto by = evaluation::relationsByScans(traj, rel, base, scans);
  EXPECT_EQ(by.at_scans.n, 2u);
  EXPECT_EQ(by.one_interval.n, 2u);
  EXPECT_EQ(by.other.n, 4u);
  EXPECT_NEAR(by.at_scans.abs_trans_mean_m, 0.1, 1e-9);
  EXPECT_NEAR(by.one_interval.abs_trans_mean_m, 0.2, 1e-9);
  EXPECT_NEAR(by.other.abs_trans_mean_m, 0.4, 1e-9);
  EXPECT_NEAR(by.at_scans.share_m, 0.2 / 8, 1e-9);
  const auto m = evaluation::relationMetrics(traj, rel, base);
  ASSERT_EQ(m.used, 8u);
  EXPECT_NEAR(by.at_scans.share_m + by.one_interval.share_m + by.other.share_m, m.abs_trans_m.mean, 1e-12);
  // An end 1 ms off a scan is at it (the default tolerance is 2 ms); 5 ms off, it is not.
  std::vector<double> near = scans;
  for (double& t : near) t += 0.001;
  EXPECT_EQ(evaluation::relationsByScans(traj, rel, base, near).at_scans.n, 2u);
  for (double& t : near) t += 0.004;
  EXPECT_EQ(evaluation::relationsByScans(traj, rel, base, near).at_scans.n, 0u);
}

TEST(Evaluation, AteIsZeroAfterARigidMotionAndSeesNoise) {
  const auto ref = circle();
  auto est = ref;
  for (auto& p : est) p.pose = common::compose({3, -2, 0.7}, p.pose);
  const auto m = evaluation::trajectoryMetrics(est, ref, false);
  EXPECT_EQ(m.matched, ref.size());
  EXPECT_NEAR(m.ate_rmse_m, 0, 1e-9);
  EXPECT_NEAR(m.rpe_rot_rmse_deg, 0, 1e-9);
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0, 0.1);
  for (auto& p : est) {
    p.pose.x += n(rng);
    p.pose.y += n(rng);
  }
  const auto noisy = evaluation::trajectoryMetrics(est, ref, false);
  EXPECT_NEAR(noisy.ate_rmse_m, 0.1 * std::sqrt(2.0), 0.03);
}

TEST(Evaluation, LoopClosuresAreClassifiedAgainstTheReference) {
  const auto ref = circle();
  std::vector<evaluation::LoopRow> loops;
  const auto truth = common::between(ref[10].pose, ref[150].pose);
  loops.push_back({10, 150, ref[10].timestamp, ref[150].timestamp, true, truth});
  loops.push_back({11, 150, ref[10].timestamp, ref[150].timestamp, true, common::compose(truth, {2.0, 0, 0})});
  loops.push_back({10, 150, ref[10].timestamp, ref[150].timestamp, false, truth});
  loops.push_back({0, 150, -50, ref[150].timestamp, true, truth});
  const auto m = evaluation::classifyLoopClosures(loops, ref, false);
  EXPECT_EQ(m.accepted, 3u);
  EXPECT_EQ(m.true_positive, 1u);
  EXPECT_EQ(m.false_positive, 1u);
  EXPECT_EQ(m.unverifiable, 1u);
  // The false one is listed with its keyframes and its error against the reference.
  ASSERT_EQ(m.false_closures.size(), 1u);
  EXPECT_EQ(m.false_closures[0].from_keyframe, 11);
  EXPECT_NEAR(m.false_closures[0].error_m, 2.0, 1e-9);
  EXPECT_NEAR(m.false_closures[0].error_deg, 0.0, 1e-9);
}

TEST(Evaluation, MalformedRelationsFileIsAnError) {
  const auto d = test::scratchDir("relations_bad");
  std::ofstream(d / "r.relations") << "1 2 3\n";
  EXPECT_THROW(evaluation::readRelations((d / "r.relations").string()), common::InputError);
  EXPECT_THROW(evaluation::readRelations((d / "none").string()), common::InputError);
}

// The real thing: the relation file of Intel against the corrected log's own poses.
TEST(Evaluation, IntelRelationsAgainstTheCorrectedLog) {
  const std::string rel = test::sharedDataPath("freiburg_slam_benchmark/relations/intel.relations");
  if (rel.empty()) GTEST_SKIP() << "../shared/data (Freiburg relations) not present";
  auto src = io::openDataSource(test::repoPath("rawlogs/intel.rawlog"));
  std::vector<io::StampedPose> ref;
  io::Measurement m;
  while (src->next(m))
    if (auto* r = std::get_if<io::ReferencePose>(&m)) ref.push_back({r->timestamp, r->pose});
  const auto relations = evaluation::readRelations(rel);
  EXPECT_EQ(relations.size(), 2984u);
  std::vector<double> odometry_times;
  {
    auto s2 = io::openDataSource(test::repoPath("rawlogs/intel.rawlog"));
    while (s2->next(m))
      if (auto* o = std::get_if<io::OdometryReading>(&m)) odometry_times.push_back(o->timestamp);
  }
  const double off = evaluation::findRelationTimeOffset(ref, relations, odometry_times);
  const auto metrics = evaluation::relationMetrics(ref, relations, off, 5.0);  // scans ~3 s apart
  EXPECT_GT(metrics.used, 2500u);
  // Relation times are odometry/scan times of the raw log: the offset is exact to the ms.
  EXPECT_NEAR(off, 976052857.337, 0.002);
  // GMapping's corrected poses, linearly interpolated between scans ~3 s apart.
  EXPECT_LT(metrics.abs_trans_m.mean, 0.2);
}

// A re-stamped log (FR079's corrected log): no relation time is a log time, yet regular sampling
// makes some (relation - log) difference frequent by chance. The offset must still be the one
// the relations were built with, known here by construction.
TEST(Evaluation, TimeOffsetWithoutSharedTimestampsFollowsTheFit) {
  // A random drive sampled every 0.1 s (not periodic: no other offset fits as well).
  std::vector<io::StampedPose> ref;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> turn(-0.3, 0.3), speed(0.0, 0.15);
  common::Pose2 p;
  for (int i = 0; i < 200; ++i) {
    ref.push_back({i * 0.1, p});
    p = common::compose(p, {speed(rng), 0, turn(rng)});
  }
  const double base = 1211.4;
  std::vector<evaluation::Relation> rel;
  std::vector<double> log_times;
  for (const auto& p : ref) log_times.push_back(p.timestamp);
  for (int i = 0; i + 6 < 200; i += 2) {
    // Relations between instants half-way between log samples (0.05 s after them).
    const double t1 = ref[static_cast<size_t>(i)].timestamp + 0.05, t2 = ref[static_cast<size_t>(i + 5)].timestamp + 0.05;
    common::Pose2 p1, p2;
    ASSERT_TRUE(evaluation::interpolatePose(ref, t1, 1.0, p1));
    ASSERT_TRUE(evaluation::interpolatePose(ref, t2, 1.0, p2));
    rel.push_back({base + t1, base + t2, common::between(p1, p2)});
  }
  const double off = evaluation::findRelationTimeOffset(ref, rel, log_times);
  EXPECT_NEAR(off, base, 0.005);
  EXPECT_LT(evaluation::relationMetrics(ref, rel, off).abs_trans_m.mean, 1e-3);
}

// A closure between two visits of a circle, checked against a relation a second away from it:
// the relation carried over those seconds by the run's nodes predicts the closure's measurement.
TEST(Evaluation, LoopsCheckedAgainstRelations) {
  // The run's nodes: a circle of radius 5 m at 0.1 rad/s, one node every 0.5 s.
  std::vector<io::StampedPose> nodes;
  const auto truth = [](double t) {
    const double a = 0.1 * t;
    return common::Pose2{5 * std::sin(a), 5 - 5 * std::cos(a), a};
  };
  for (double t = 0; t <= 130; t += 0.5) nodes.push_back({t, truth(t)});
  // The relation between t = 10 and t = 73.8 (one lap and a little later): exact.
  const std::vector<evaluation::Relation> rel{{10.0, 73.8, common::between(truth(10.0), truth(73.8))}};
  evaluation::LoopRow good, bad, far;
  good.accepted = bad.accepted = far.accepted = true;
  good.from_time = bad.from_time = 11.0;
  good.to_time = bad.to_time = 75.0;
  good.measurement = common::between(truth(11.0), truth(75.0));
  bad.measurement = common::compose(good.measurement, {0.8, 0.0, 0.0});  // 0.8 m along the path
  far.from_time = 40.0;                                                  // no relation near these times
  far.to_time = 100.0;
  const auto c = evaluation::checkLoopsWithRelations({good, bad, far}, nodes, rel, 0.0);
  EXPECT_EQ(c.accepted, 3u);
  EXPECT_EQ(c.checked, 2u);
  ASSERT_EQ(c.contradicted, 1u);
  EXPECT_NEAR(c.contradictions[0].error_m, 0.8, 1e-2);
  EXPECT_DOUBLE_EQ(c.contradictions[0].from_time, 11.0);
}
