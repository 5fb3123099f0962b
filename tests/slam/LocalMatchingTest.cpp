#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "TestPaths.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

// The pipeline run on the log to t1 with loop closing off, and the log's corrected poses (the
// reference) by time.
struct LocalRun {
  std::unique_ptr<slam::Pipeline> pipeline;
  std::map<double, common::Pose2> reference;
};

LocalRun runWithoutClosures(const std::string& log, slam::PipelineOptions o, double t1) {
  o.loop_closure.enabled = false;
  LocalRun run{std::make_unique<slam::Pipeline>(o), {}};
  auto src = io::openDataSource(log);
  while (run.pipeline->step(*src) && run.pipeline->stats().last_timestamp <= t1) {
  }
  run.pipeline->finish();
  for (const auto& r : run.pipeline->referenceTrajectory()) run.reference[r.timestamp] = r.pose;
  return run;
}

// The errors of the keyframe increments ending between t0 and t1 against the reference.
std::vector<common::Pose2> incrementErrors(const std::string& log, const slam::PipelineOptions& o, double t0, double t1) {
  const LocalRun run = runWithoutClosures(log, o, t1);
  const auto& ref = run.reference;
  const auto& kf = run.pipeline->keyframes();
  std::vector<common::Pose2> errors;
  for (size_t k = 1; k < kf.size(); ++k) {
    if (kf[k].timestamp < t0 || kf[k].timestamp > t1) continue;
    const auto a = ref.find(kf[k - 1].timestamp), b = ref.find(kf[k].timestamp);
    if (a == ref.end() || b == ref.end()) continue;
    errors.push_back(common::between(common::between(a->second, b->second), common::between(kf[k - 1].pose, kf[k].pose)));
  }
  return errors;
}

// How many of those increments are more than 0.5 m off.
int wrongIncrements(const std::string& log, const slam::PipelineOptions& o, double t0, double t1) {
  int wrong = 0;
  for (const auto& e : incrementErrors(log, o, t0, t1)) wrong += std::hypot(e.x, e.y) > 0.5 ? 1 : 0;
  return wrong;
}

// The largest heading error of those increments [deg].
double worstHeadingError(const std::string& log, const slam::PipelineOptions& o, double t0, double t1) {
  double worst = 0;
  for (const auto& e : incrementErrors(log, o, t0, t1)) worst = std::max(worst, std::abs(e.phi) * 180 / M_PI);
  return worst;
}

// The worst heading error [deg] of the increments between t0 and t1 with the options `o`, and
// with `off` applied to them (the rule under test switched off).
struct WithAndWithout {
  double with, without;
};
template <class Off>
WithAndWithout worstHeadingWithAndWithout(const std::string& log, const slam::PipelineOptions& o, Off off, double t0, double t1) {
  slam::PipelineOptions without = o;
  off(without);
  return {worstHeadingError(log, o, t0, t1), worstHeadingError(log, without, t0, t1)};
}

// Mean error [m, deg] of the trajectory at the scan times that are not keyframes, each relative
// to the keyframe before it, against the log's corrected poses (to t1, loop closing off).
std::pair<double, double> betweenKeyframeError(const std::string& log, const slam::PipelineOptions& o, double t1) {
  const LocalRun run = runWithoutClosures(log, o, t1);
  const auto& ref = run.reference;
  std::map<double, common::Pose2> ours, kf;
  for (const auto& s : run.pipeline->odometryTrajectory()) ours[s.timestamp] = s.pose;
  for (const auto& k : run.pipeline->keyframes()) kf[k.timestamp] = k.pose;
  double sum_m = 0, sum_deg = 0;
  int n = 0;
  for (const auto& [t, ref_pose] : ref) {
    if (kf.count(t) || t > t1) continue;
    auto k = kf.upper_bound(t);
    if (k == kf.begin()) continue;
    --k;
    const auto rk = ref.find(k->first);
    const auto o_at = ours.find(t);
    if (rk == ref.end() || o_at == ours.end()) continue;
    const common::Pose2 e = common::between(common::between(rk->second, ref_pose), common::between(k->second, o_at->second));
    sum_m += std::hypot(e.x, e.y);
    sum_deg += std::abs(e.phi) * 180 / M_PI;
    ++n;
  }
  return {n ? sum_m / n : 0.0, n ? sum_deg / n : 0.0};
}

}  // namespace

// FR079 between 302 s and 309 s: the robot reverses while its odometry reports driving forwards
// (laser scans and corrected poses agree it goes backwards), about 0.6 m per keyframe. With the
// old rule (no correction beyond 0.5 m, no restarts) all six keyframes there keep the
// odometry's wrong direction. Trusted matches and restarts from the reversed odometry fix the
// first ones (two later keyframes of the episode are still wrong: their submap is poor).
TEST(LocalMatching, TrustedMatchCorrectsOdometryThatReportsReversingAsForwards) {
  const std::string log = test::sharedDataPath("freiburg_slam_benchmark/corrected_logs/freiburg-079-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data (Freiburg corrected logs) not present";
  slam::PipelineOptions o;
  o.input.laser_labels = "FLASER";
  o.local.retry_below_fraction = 0.8;
  const int now = wrongIncrements(log, o, 302, 309);
  slam::PipelineOptions old = o;
  old.local.max_trusted_correction_m = 0;
  old.local.max_trusted_correction_deg = 0;
  old.local.retry_below_fraction = 0;
  const int before = wrongIncrements(log, old, 302, 309);
  EXPECT_GE(before, 5);
  EXPECT_LE(now, 2);
}

// Freiburg campus, scans 237 -> 239 (the log has no timestamps: time is the scan number): the
// odometry turns 22° (wheel slip), the corrected log 3.8°, and PL-ICP from standing still 0.5°.
// PL-ICP from the odometry's heading fails, so before the retry from the odometry's translation
// without its turn the step kept the false turn (18° off the log; checked by removing that start).
TEST(LocalMatching, RetryWithoutTheTurnCorrectsAFalseOdometryTurn) {
  const std::string log = test::sharedDataPath("freiburg_slam_benchmark/corrected_logs/freiburg-campus-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data (Freiburg corrected logs) not present";
  const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/freiburg-campus.ini"));
  ASSERT_GT(o.local.retry_below_fraction, 0);
  const auto e = worstHeadingWithAndWithout(log, o, [](slam::PipelineOptions& w) { w.local.retry_below_fraction = 0; }, 238, 240);
  EXPECT_GT(e.without, 15);
  EXPECT_LT(e.with, 5);
}

// The same FR079 episode with ini/fr079.ini. At 308.4 s the robot reverses 0.53 m; the odometry
// says it drove 0.51 m forwards. PL-ICP against the submap ends at the reversing pose from
// every start (odometry, standing still, reversed, without the turn), but explains only 64 % of
// the scan, under trusted_matched_fraction 0.7, so the 1 m correction was refused and the
// odometry kept. A single minimum reached from all starts is trusted.
TEST(LocalMatching, MatchThatEveryStartReachesIsTrusted) {
  const std::string log = test::sharedDataPath("freiburg_slam_benchmark/corrected_logs/freiburg-079-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data (Freiburg corrected logs) not present";
  const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
  ASSERT_TRUE(o.local.trust_agreeing_starts);
  slam::PipelineOptions without_rule = o;
  without_rule.local.trust_agreeing_starts = false;
  EXPECT_EQ(wrongIncrements(log, without_rule, 308, 309), 1);
  EXPECT_EQ(wrongIncrements(log, o, 308, 309), 0);
  EXPECT_LE(wrongIncrements(log, o, 302, 309), 1);  // 306.3 s: no start finds the reversing pose
}

// FR079 keeps a scan every 0.2 s, a keyframe every 0.5 m / 10°: three scans in four are not
// keyframes. Matched with the submap, they carry the trajectory at odometry times between
// keyframes, where the odometry alone misses part of the turns. To 200 s: 0.022 m / 0.38° with
// the matches, 0.041 m / 1.21° from the odometry alone.
TEST(LocalMatching, ScansBetweenKeyframesFollowTheirSubmapMatch) {
  const std::string log = test::sharedDataPath("freiburg_slam_benchmark/corrected_logs/freiburg-079-corrected.log.gz");
  if (log.empty()) GTEST_SKIP() << "../shared/data (Freiburg corrected logs) not present";
  const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/fr079.ini"));
  ASSERT_TRUE(o.local.match_every_scan);
  slam::PipelineOptions odometry_only = o;
  odometry_only.local.match_every_scan = false;
  const auto [with_m, with_deg] = betweenKeyframeError(log, o, 200);
  const auto [without_m, without_deg] = betweenKeyframeError(log, odometry_only, 200);
  std::printf("between keyframes: matched %.4f m %.3f deg, odometry %.4f m %.3f deg\n", with_m, with_deg, without_m, without_deg);
  EXPECT_LT(with_m, 0.7 * without_m);
  EXPECT_LT(with_deg, 0.5 * without_deg);
}

// Intel (the shipped rawlog), 100-165 s, loop closing off. PL-ICP from the odometry with the
// default 4 m first gate turns two keyframe steps 5.7° and 5.0° away from the corrected log
// (116.3 s and 159.8 s): clutter far from the walls is associated in the first iterations and
// drags the match off. Also aligning from the odometry with a 1 m first gate, and keeping that
// match unless the wide one explains 5 % more of the scan, leaves every step there within 2°.
TEST(LocalMatching, NarrowFirstGateKeepsAGoodOdometryGuess) {
  const std::string log = test::repoPath("rawlogs/intel.rawlog");
  const slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/intel.ini"));
  ASSERT_GT(o.local.fine_start_gate_m, 0);
  const auto e = worstHeadingWithAndWithout(log, o, [](slam::PipelineOptions& w) { w.local.fine_start_gate_m = 0; }, 100, 165);
  EXPECT_GT(e.without, 4.5);
  EXPECT_LT(e.with, 2.5);
}
