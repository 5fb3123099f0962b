#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <memory>

#include "TestPaths.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/LoopCloser.h"
#include "urbanslam/slam/Pipeline.h"

using namespace urbanslam;

namespace {

constexpr double kDeg = M_PI / 180.0;

// Two scans of the shipped Intel rawlog, 870 s apart in the same corridor, with the log's
// corrected poses (GMapping's, the independent reference).
struct Pair {
  std::vector<slam::Keyframe> keyframes;
  common::Pose2 truth;  // pose of the second scan in the first's frame, from the corrected poses
};

Pair intelPair(size_t a, size_t b) {
  auto src = io::openDataSource(test::repoPath("rawlogs/intel.rawlog"));
  std::vector<io::LaserScan> scans;
  std::vector<common::Pose2> ref;
  io::Measurement m;
  while (src->next(m)) {
    if (auto* s = std::get_if<io::LaserScan>(&m)) scans.push_back(*s);
    if (auto* r = std::get_if<io::ReferencePose>(&m)) ref.push_back(r->pose);
  }
  Pair p;
  if (std::max(a, b) >= scans.size() || scans.size() != ref.size()) return p;
  p.keyframes.push_back({0, scans[a].timestamp, ref[a], scans[a], false, {}});
  p.keyframes.push_back({1, scans[b].timestamp, ref[b], scans[b], false, {}});
  p.truth = common::between(ref[a], ref[b]);
  return p;
}

// A filter in which the second pose sits at `estimate` from the first, known to 0.3 m and 3°
// (PL-ICP territory for the auto method), as a drifted map would have it before the loop closes.
std::unique_ptr<esdf::Esdf> filterWith(const common::Pose2& first, const common::Pose2& estimate) {
  auto out = std::make_unique<esdf::Esdf>();
  esdf::Esdf& f = *out;
  f.initialise(esdf::toVec(first), esdf::Mat3::Identity() * 1e-9);
  const esdf::Mat3 cov = esdf::Vec3(0.3 * 0.3, 0.3 * 0.3, 3 * kDeg * 3 * kDeg).asDiagonal();
  f.augmentRelative(0, esdf::toVec(estimate), cov.inverse());
  f.recover();
  return out;
}

double distance(const common::Pose2& a, const common::Pose2& b) {
  const common::Pose2 e = common::between(a, b);
  return std::hypot(e.x, e.y);
}

}  // namespace

// Scans 149 and 464: a run of the pipeline started PL-ICP 1.1 m off along the corridor and
// accepted the aliased minimum there (it matches fewer points than the true one). The
// ambiguity test must refuse it; without the test it passes alignment and gate.
TEST(LoopCloser, AliasedMinimumAlongACorridorIsRefused) {
  Pair p = intelPair(149, 464);
  ASSERT_EQ(p.keyframes.size(), 2u) << "rawlogs/intel.rawlog: scans or reference poses missing";
  ASSERT_GT(distance(p.truth, {}), 1.0);
  const common::Pose2 drifted{0.126, 0.130, -0.179};  // where the drifted map put scan 464
  ASSERT_GT(distance(p.truth, drifted), 1.0);

  slam::LoopClosureOptions off;  // everything else at the defaults
  off.ambiguity_offset_m = 0;
  auto f1 = filterWith(p.keyframes[0].pose, drifted);
  const auto wrong = slam::LoopCloser(off).tryClose(*f1, p.keyframes, 0, 1, false);
  ASSERT_TRUE(wrong.accepted) << wrong.reason;
  EXPECT_GT(distance(p.truth, wrong.measurement), 1.0);  // a false closure against the reference

  slam::LoopClosureOptions on = off;
  on.ambiguity_offset_m = 0.75;
  auto f2 = filterWith(p.keyframes[0].pose, drifted);
  const auto refused = slam::LoopCloser(on).tryClose(*f2, p.keyframes, 0, 1, false);
  EXPECT_FALSE(refused.accepted);
  EXPECT_EQ(refused.reason, "ambiguous");

  // From a correct estimate the same test lets the true closure through.
  auto f3 = filterWith(p.keyframes[0].pose, p.truth);
  const auto right = slam::LoopCloser(on).tryClose(*f3, p.keyframes, 0, 1, false);
  EXPECT_TRUE(right.accepted) << right.reason;
  EXPECT_LT(distance(p.truth, right.measurement), 0.1);
  EXPECT_LT(std::abs(common::between(p.truth, right.measurement).phi), 2 * kDeg);
}
