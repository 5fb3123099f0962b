// Two sessions mapped separately, each in its own frame, then joined and optimised as one map,
// checked against references independent of the join: the trajectory of one mapping run over
// the whole log (whose frame is the first session's: both start at the same first scan) and the
// benchmark relations of the FR079 excerpt (Kümmerle et al. 2009). The first session is the
// excerpt's first 600 scans, the second the other 600, which start where the first ended.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>

#include "SkippingSource.h"
#include "TestPaths.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/slam/MapFile.h"
#include "urbanslam/slam/MapSession.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/SessionJoin.h"

using namespace urbanslam;

namespace {

constexpr size_t kFirstScans = 600;

std::string excerpt() { return test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz"); }

slam::PipelineOptions options() { return slam::loadPipelineOptions(test::repoPath("ini/fr079.ini")); }

// One run over the whole excerpt: the reference trajectory.
const slam::Pipeline& fullRun() {
  static const std::unique_ptr<slam::Pipeline> full = [] {
    auto p = std::make_unique<slam::Pipeline>(options());
    p->run(*io::openDataSource(excerpt()));
    return p;
  }();
  return *full;
}

struct Sessions {
  std::unique_ptr<slam::Pipeline> first, second;
  const slam::Pipeline* full = &fullRun();
};

// Fresh for each test that joins them: appendSession changes the first session.
Sessions sessions() {
  Sessions s;
  const slam::PipelineOptions o = options();
  s.first = std::make_unique<slam::Pipeline>(o);
  auto src = io::openDataSource(excerpt());
  while (s.first->stats().scans < kFirstScans && s.first->step(*src)) {
  }
  s.first->waitForGlobalSlam(*src);
  s.second = std::make_unique<slam::Pipeline>(o);
  test::SkippingSource rest(io::openDataSource(excerpt()), s.first->stats().measurements);
  s.second->runInput(rest);
  return s;
}

common::Pose2 at(const slam::Pipeline& p, double t) {
  common::Pose2 out;
  EXPECT_TRUE(evaluation::interpolatePose(p.scanTrajectory(), t, 1.0, out)) << t;
  return out;
}

// Relation errors of `p`'s scans for the relations with both ends before `split` (part 0),
// both after (part 1) and one on each side (part 2).
std::array<evaluation::RelationMetrics, 3> byPart(const slam::Pipeline& p, double split) {
  const auto relations = evaluation::readRelations(test::repoPath("rawlogs/fr079-raw-excerpt.relations"));
  std::array<std::vector<evaluation::Relation>, 3> parts;
  for (const auto& r : relations) {
    const bool before = std::min(r.t1, r.t2) < split, after = std::max(r.t1, r.t2) >= split;
    parts[before && after ? 2 : before ? 0 : 1].push_back(r);
  }
  std::array<evaluation::RelationMetrics, 3> out;
  for (size_t i = 0; i < 3; ++i) out[i] = evaluation::relationMetrics(p.scanTrajectory(), parts[i], 0.0, 0.5);
  return out;
}

// Two finished maps joined offline. The join puts the second session's keyframes where the full
// run has them. Then each session's relations are met as well as that session met them alone
// (the merge keeps every keyframe constraint the sessions made), the relations across the two
// are met, and loops close across them. (The second session's own constraints were made without
// the first map; a log mapped into the map, below, does better.)
void twoMapsAreJoinedWhereTheFullRunHasThemAndKeepEachSessionsAccuracy(Sessions& s) {
  const size_t n0 = s.first->keyframes().size(), n1 = s.second->keyframes().size();
  const double split = s.second->keyframes().front().timestamp;
  const auto first_alone = byPart(*s.first, split), second_alone = byPart(*s.second, split);
  const slam::SessionJoin join = slam::findSessionJoin(s.first->map(), s.first->options(), s.second->map());
  ASSERT_TRUE(join.joined) << join.reason;
  EXPECT_GE(join.agreeing_scans, 4u);
  double worst_m = 0, worst_deg = 0;
  for (size_t i : join.agreeing) {
    const slam::Keyframe& k = s.second->keyframes()[join.fixes[i].keyframe];
    const common::Pose2 placed = common::compose(join.transform, k.pose), truth = at(*s.full, k.timestamp);
    worst_m = std::max(worst_m, std::hypot(placed.x - truth.x, placed.y - truth.y));
    worst_deg = std::max(worst_deg, std::abs(common::wrapToPi(placed.phi - truth.phi)) * 180 / M_PI);
  }
  EXPECT_LT(worst_m, 0.5);
  EXPECT_LT(worst_deg, 3.0);
  s.first->appendSession(*s.second, join);
  s.first->finish();
  ASSERT_EQ(s.first->keyframes().size(), n0 + n1);
  size_t across = 0;
  for (const auto& r : s.first->loopClosures()) across += r.accepted && r.from < n0 && r.to >= n0;
  EXPECT_GE(across, 5u);

  const auto merged = byPart(*s.first, split), full = byPart(*s.full, split);
  ASSERT_GE(merged[1].used, 100u);
  ASSERT_GE(merged[2].used, 20u);
  EXPECT_LT(merged[0].abs_trans_m.mean, 1.05 * first_alone[0].abs_trans_m.mean + 0.002);
  EXPECT_LT(merged[1].abs_trans_m.mean, 1.05 * second_alone[1].abs_trans_m.mean + 0.002);
  EXPECT_LT(merged[1].abs_rot_deg.mean, 1.05 * second_alone[1].abs_rot_deg.mean + 0.02);
  // Across the sessions as well as within the second one.
  EXPECT_LT(merged[2].abs_trans_m.mean, 1.1 * merged[1].abs_trans_m.mean);
  EXPECT_LT(merged[2].abs_rot_deg.mean, 1.1 * merged[1].abs_rot_deg.mean);
  std::cerr << "relations (first / second / across): merged " << merged[0].abs_trans_m.mean << " / " << merged[1].abs_trans_m.mean << " / "
            << merged[2].abs_trans_m.mean << " m, full run " << full[0].abs_trans_m.mean << " / " << full[1].abs_trans_m.mean << " / "
            << full[2].abs_trans_m.mean << " m, second session alone " << second_alone[1].abs_trans_m.mean << " m; " << across
            << " closures across\n";
}

// The second half of the log mapped into the map of the first, with no idea where it starts.
// It starts where the first ended but leaves at once for a room the first never saw, so it is
// joined only when it comes back (about 1446 s); from then on it continues inside the map. (A
// log of another building is never joined.)
// Between scans less than 5 s apart (most relations) it is then as good as the one run over the
// whole log, except in its first 10 s: it started with an empty submap where the one run had the
// first half's.
void aLogMappedIntoAMapMeetsTheRelationsAsTheFullRunDoes(Sessions& s) {
  const size_t n0 = s.first->keyframes().size();
  const double split = s.second->keyframes().front().timestamp, end = s.full->keyframes().back().timestamp;
  {
    // A session from another building is not joined, however many of its scans look like one.
    slam::Pipeline intel(slam::PipelineOptions{});
    intel.runInput(*io::openDataSource(test::repoPath("rawlogs/intel-corrected-excerpt.log.gz")));
    const slam::SessionJoin other = slam::findSessionJoin(s.first->map(), s.first->options(), intel.map());
    EXPECT_FALSE(other.joined) << other.agreeing_scans << " scans support a join (" << other.fixes.size() << " fixes)";
    EXPECT_GT(other.probes, 10u);
  }
  test::SkippingSource rest(io::openDataSource(excerpt()), s.first->stats().measurements);
  slam::SessionRun run = slam::runSessionInMap(std::move(s.first), rest);
  ASSERT_TRUE(run.join.joined) << run.join.reason;
  EXPECT_EQ(run.keyframes_before, n0);
  EXPECT_GT(run.joined_at_s, split);
  EXPECT_LT(run.joined_at_s, end - 10);  // with log left to continue in the map
  run.pipeline->finish();
  ASSERT_GT(run.pipeline->keyframes().size(), n0 + 100);

  const auto relations = evaluation::readRelations(test::repoPath("rawlogs/fr079-raw-excerpt.relations"));
  std::vector<evaluation::Relation> short_after, first_half;
  for (const auto& r : relations) {
    if (std::max(r.t1, r.t2) < split) first_half.push_back(r);
    if (std::min(r.t1, r.t2) >= split + 10 && std::abs(r.t2 - r.t1) < 5) short_after.push_back(r);
  }
  ASSERT_GE(short_after.size(), 80u);
  const auto m = evaluation::relationMetrics(run.pipeline->scanTrajectory(), short_after, 0.0, 0.5);
  const auto f = evaluation::relationMetrics(s.full->scanTrajectory(), short_after, 0.0, 0.5);
  EXPECT_EQ(m.used, short_after.size());
  EXPECT_LT(m.abs_trans_m.mean, 1.05 * f.abs_trans_m.mean + 0.001);
  EXPECT_LT(m.abs_rot_deg.mean, 1.05 * f.abs_rot_deg.mean + 0.01);
  // The map's own part is untouched in accuracy.
  const auto m0 = evaluation::relationMetrics(run.pipeline->scanTrajectory(), first_half, 0.0, 0.5);
  const auto f0 = evaluation::relationMetrics(s.full->scanTrajectory(), first_half, 0.0, 0.5);
  EXPECT_LT(m0.abs_trans_m.mean, 1.05 * f0.abs_trans_m.mean + 0.001);
  std::cerr << "relations after the session's first 10 s: mapped into the map " << m.abs_trans_m.mean << " m " << m.abs_rot_deg.mean
            << " deg, one run " << f.abs_trans_m.mean << " m " << f.abs_rot_deg.mean << " deg; joined " << run.joined_at_s - split
            << " s after the split\n";
}

}  // namespace

// The two halves of the excerpt: the sessions (and the run over the whole excerpt) are made once
// for both checks, the first half's map saved and loaded again for the second (a loaded map
// continues exactly as the one in memory: MapResume).
TEST(SessionMerge, TheSecondHalfJoinsTheFirstOfflineAndAsItIsMapped) {
  Sessions s = sessions();
  const auto path = test::scratchDir("session_merge") / "first.usmap";
  slam::saveMap(*s.first, path.string());
  {
    SCOPED_TRACE("merge");
    twoMapsAreJoinedWhereTheFullRunHasThemAndKeepEachSessionsAccuracy(s);
  }
  s.first = slam::loadMap(path.string());
  {
    SCOPED_TRACE("run --map");
    aLogMappedIntoAMapMeetsTheRelationsAsTheFullRunDoes(s);
  }
}
