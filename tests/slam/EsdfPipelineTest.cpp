#include <gtest/gtest.h>

#include <cmath>

#include "TestPaths.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

std::unique_ptr<slam::Pipeline> runOn(const std::string& log, slam::PipelineOptions o) {
  auto p = std::make_unique<slam::Pipeline>(o);
  auto src = io::openDataSource(log);
  p->run(*src);
  return p;
}

double ateAgainstReference(const slam::Pipeline& p) {
  std::vector<io::StampedPose> kf;
  for (const auto& k : p.keyframes()) kf.push_back({k.timestamp, k.pose});
  return evaluation::trajectoryMetrics(kf, p.referenceTrajectory(), false).ate_rmse_m;
}

// Rebuilds the filter from the constraints the pipeline reported (independent of its internals).
std::unique_ptr<esdf::Esdf> rebuild(const slam::Pipeline& p) {
  auto out = std::make_unique<esdf::Esdf>();
  esdf::Esdf& f = *out;
  f.initialise(esdf::Vec3::Zero(), esdf::Mat3::Identity() * 1e-9);
  for (const auto& e : p.graphEdges())
    if (!e.loop_closure) f.augmentRelative(static_cast<int>(e.from), esdf::toVec(e.measurement), e.information);
  for (const auto& e : p.graphEdges())
    if (e.loop_closure) f.observeRelative(static_cast<int>(e.from), static_cast<int>(e.to), esdf::toVec(e.measurement), e.information);
  f.recover();
  return out;
}

}  // namespace

// The shipped Intel rawlog: the ESDF with scan matching and loop closures must beat dead
// reckoning by a wide margin against the log's reference trajectory.
TEST(EsdfPipeline, BeatsDeadReckoningOnTheShippedRawlog) {
  const std::string log = test::repoPath("rawlogs/intel.rawlog");
  slam::PipelineOptions dr;
  dr.estimator.type = slam::EstimatorOptions::Type::DeadReckoning;
  dr.local.scan_matching = false;
  const double ate_dr = ateAgainstReference(*runOn(log, dr));
  const auto slam_run = runOn(log, slam::PipelineOptions{});
  const double ate = ateAgainstReference(*slam_run);
  RecordProperty("ate_dead_reckoning_m", std::to_string(ate_dr));
  RecordProperty("ate_esdf_m", std::to_string(ate));
  EXPECT_GT(ate_dr, 15.0);
  EXPECT_LT(ate, 0.5 * ate_dr);
  EXPECT_GT(slam_run->stats().closures_accepted, 10u);
  // The pipeline's keyframe poses are the optimum of the constraints it reports.
  const auto f = rebuild(*slam_run);
  for (size_t i = 0; i < slam_run->keyframes().size(); i += 50) {
    EXPECT_NEAR(f->mean(static_cast<int>(i)).x(), slam_run->keyframes()[i].pose.x, 1e-3) << i;
    EXPECT_NEAR(f->mean(static_cast<int>(i)).y(), slam_run->keyframes()[i].pose.y, 1e-3) << i;
  }
}

TEST(EsdfPipeline, SameInputSameOutput) {
  const std::string log = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  const auto a = runOn(log, {}), b = runOn(log, {});
  ASSERT_EQ(a->keyframes().size(), b->keyframes().size());
  for (size_t i = 0; i < a->keyframes().size(); ++i) {
    EXPECT_EQ(a->keyframes()[i].pose.x, b->keyframes()[i].pose.x);
    EXPECT_EQ(a->keyframes()[i].pose.phi, b->keyframes()[i].pose.phi);
  }
  EXPECT_EQ(a->loopClosures().size(), b->loopClosures().size());
}

// Keyframe scans pushed out to the spill file and read back (no cache at all) make the same
// map as scans held in memory: the store is invisible to the estimate.
TEST(EsdfPipeline, SpilledScansMakeTheSameMap) {
  const std::string log = test::repoPath("rawlogs/fr079-raw-excerpt.clf.gz");  // closes loops
  slam::PipelineOptions spilled;
  spilled.map.scan_cache_mb = 0;
  const auto a = runOn(log, {}), b = runOn(log, spilled);
  EXPECT_EQ(a->map().scans().spilledBytes(), 0u);
  EXPECT_EQ(b->map().scans().residentBytes(), 0u);
  EXPECT_GT(b->map().scans().spilledBytes(), 500u * a->keyframes().size());
  ASSERT_EQ(a->keyframes().size(), b->keyframes().size());
  for (size_t i = 0; i < a->keyframes().size(); ++i) {
    ASSERT_EQ(a->keyframes()[i].pose.x, b->keyframes()[i].pose.x) << i;
    ASSERT_EQ(a->keyframes()[i].pose.phi, b->keyframes()[i].pose.phi) << i;
  }
  const auto a_closures = a->loopClosures(), b_closures = b->loopClosures();
  ASSERT_EQ(a_closures.size(), b_closures.size());
  size_t accepted = 0;
  for (size_t i = 0; i < a_closures.size(); ++i) {
    EXPECT_EQ(a_closures[i].accepted, b_closures[i].accepted) << i;
    accepted += a_closures[i].accepted;
  }
  EXPECT_GT(accepted, 0u);  // the closures read earlier keyframes' scans back
}

// A deliberately corrupted candidate: keyframe k's scan replaced by keyframe i's, although the
// filter knows they are metres apart. Alignment then "succeeds" perfectly (identical scans), so
// only the innovation gate stands between it and the map — and it must reject it.
TEST(EsdfPipeline, WrongPlaceClosureIsGatedOut) {
  const std::string log = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  slam::PipelineOptions o;
  o.loop_closure.enabled = false;
  const auto p = runOn(log, o);
  auto filter = rebuild(*p);
  esdf::Esdf& f = *filter;
  const auto& keyframes = p->keyframes();
  const size_t k = keyframes.size() - 1;
  size_t i = 0;
  while (i < k && std::hypot(keyframes[i].pose.x - keyframes[k].pose.x, keyframes[i].pose.y - keyframes[k].pose.y) < 3.0) ++i;
  ASSERT_LT(i, k) << "the excerpt has no keyframe 3 m away from the last one";
  slam::Map corrupted(nullptr, 1.0);
  for (const slam::Keyframe& kf : keyframes) corrupted.addKeyframe(kf, io::CompactScan(p->map().scan(kf.index == k ? i : kf.index)));
  slam::LoopClosureOptions lo;
  lo.method = slam::LoopClosureOptions::Method::CrfIcp;  // finds the (wrong) perfect match from metres away
  lo.min_constraint_ratio = 0;                           // the other refusals off: this is about the gate
  lo.ambiguity_offset_m = 0;
  lo.max_free_space_conflict = 1;
  lo.view_test = false;
  const size_t factors_before = f.factorCount();
  const slam::LoopClosureRecord r = slam::LoopCloser(lo).tryClose(f, corrupted, i, k);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, slam::ClosureReason::Gating) << "rms " << r.rms_m;
  EXPECT_GT(r.mahalanobis2, r.gate_threshold);
  EXPECT_EQ(f.factorCount(), factors_before);  // nothing touched the filter
  // The view test knows it before aligning: nowhere the gate admits do the two scans (the same
  // scan, metres from where the filter puts the pair) overlap enough.
  lo.view_test = true;
  const slam::LoopClosureRecord v = slam::LoopCloser(lo).tryClose(f, corrupted, i, k);
  EXPECT_FALSE(v.accepted);
  EXPECT_EQ(v.reason, slam::ClosureReason::NoOverlap);
  EXPECT_EQ(f.factorCount(), factors_before);
}
