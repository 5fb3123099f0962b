// Sessions of a simulated city joined with no pose given, checked against the simulator's truth.
// A drive through a small city is cut in two; each half is mapped in its own frame with the
// shipped pipeline. The second half drives streets the first one drove, so it must be found in
// the first half's map: where it lies (its fixes against the truth) and through the laser
// classifier's detections, since a single scan of a street is ambiguous along it for the
// exhaustive place search. A drive through another city, with streets and facades of the same
// kind, must never be joined.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <Eigen/LU>

#include "SkippingSource.h"
#include "TestPaths.h"
#include "urbanslam/evaluation/Evaluation.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/SessionJoin.h"

using namespace urbanslam;

namespace {

sim::SimOptions drive(int city_seed) {
  sim::SimOptions o = sim::loadSimOptions(test::repoPath("ini/city-1km2.ini"));
  o.city.seed = city_seed;
  o.city.area_km2 = 0.25;
  o.route.route_length_km = 2.0;
  return o;
}

slam::PipelineOptions pipelineOptions() {
  slam::PipelineOptions o = slam::loadPipelineOptions(test::repoPath("ini/default.ini"));
  slam::resolveDefaultPaths(o, URBANSLAM_SOURCE_DIR);
  return o;
}

struct Halves {
  std::unique_ptr<slam::Pipeline> first, second;
};

// The drive's first half of its scans, then the rest, each mapped alone (once per city).
const Halves& halves(int city_seed) {
  static std::map<int, Halves> made;
  if (const auto it = made.find(city_seed); it != made.end()) return it->second;
  const double share = 0.5;
  const sim::SimOptions so = drive(city_seed);
  Halves h;
  h.first = std::make_unique<slam::Pipeline>(pipelineOptions());
  sim::SimulatedSource src(so);
  const size_t scans = static_cast<size_t>(share * so.route.route_length_km * 1000.0 / so.route.speed_mps * so.laser.rate_hz);
  while (h.first->stats().scans < scans && h.first->step(src)) {
  }
  h.first->waitForGlobalSlam(src);
  h.second = std::make_unique<slam::Pipeline>(pipelineOptions());
  test::SkippingSource rest(std::make_unique<sim::SimulatedSource>(so), h.first->stats().measurements);
  h.second->runInput(rest);
  return made[city_seed] = std::move(h);
}

// The true pose at `t` (in either half's reference) in the frame of the first half's first
// keyframe.
common::Pose2 truthInMap(const Halves& h, double t) {
  const auto truth = [&](double at) {
    common::Pose2 p;
    const bool found = evaluation::interpolatePose(h.first->referenceTrajectory(), at, 0.2, p) ||
                       evaluation::interpolatePose(h.second->referenceTrajectory(), at, 0.2, p);
    EXPECT_TRUE(found) << "no true pose at " << at;
    return p;
  };
  return common::between(truth(h.first->keyframes().front().timestamp), truth(t));
}

}  // namespace

TEST(SessionJoinCity, FindsTheSecondHalfOfADriveWhereTheTruthPutsIt) {
  const Halves& h = halves(1);
  const slam::Map& map = h.first->map();
  const slam::Map& session = h.second->map();

  const slam::SessionJoin join = slam::findSessionJoin(map, h.first->options(), session);
  ASSERT_TRUE(join.joined) << join.reason << " (" << join.probes << " place searches, " << join.fixes.size() << " fixes)";
  EXPECT_GE(join.agreeing_scans, 4u);
  // Every fix of the join, and every scan that confirmed it, where the truth has it.
  size_t by_classifier = 0, checked = 0;
  for (size_t i : join.agreeing) {
    const slam::SessionFix& f = join.fixes[i];
    by_classifier += f.detector == slam::Proposer::Laser ? 1 : 0;
    const common::Pose2 truth = truthInMap(h, session.keyframes()[f.keyframe].timestamp);
    EXPECT_LT(std::hypot(f.pose.x - truth.x, f.pose.y - truth.y), 0.5) << slam::proposerName(f.detector) << " fix of keyframe " << f.keyframe;
    EXPECT_LT(std::abs(common::wrapToPi(f.pose.phi - truth.phi)), 1.0 * M_PI / 180);
    for (size_t k : f.confirmed) {
      const common::Pose2 placed = common::compose(f.transform, session.keyframes()[k].pose);
      const common::Pose2 t = truthInMap(h, session.keyframes()[k].timestamp);
      EXPECT_LT(std::hypot(placed.x - t.x, placed.y - t.y), 1.0) << "keyframe " << k << " confirming the fix of " << f.keyframe;
      ++checked;
    }
  }
  EXPECT_GE(by_classifier, 1u) << "the join should come from the classifier's detections";
  EXPECT_GE(checked, 3u);
  // The join's transform puts the session's first keyframe where the truth has it, within the
  // uncertainty it states.
  const common::Pose2 first = truthInMap(h, session.keyframes().front().timestamp);
  const Eigen::Vector3d e(join.transform.x - first.x, join.transform.y - first.y, common::wrapToPi(join.transform.phi - first.phi));
  EXPECT_LT(e.dot(join.transform_cov.inverse() * e), 11.34) << e.transpose();  // chi-square, 3 dof, 99 %
}

TEST(SessionJoinCity, NeverJoinsADriveThroughAnotherCity) {
  const Halves &here = halves(1), &elsewhere = halves(2);
  const slam::SessionJoin join = slam::findSessionJoin(here.first->map(), here.first->options(), elsewhere.second->map());
  EXPECT_FALSE(join.joined) << join.agreeing_scans << " scans support a join at " << join.transform.x << ", " << join.transform.y;
  EXPECT_GT(join.probes, 100u);
}
