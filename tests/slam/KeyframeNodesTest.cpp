// Keyframes hung from the filter poses of others (a reduced pose graph), against plain filters
// in which every keyframe is a pose of its own and every measurement goes in once: with no
// closure the reduction is that chain with its inner poses marginalised out (exact), and with
// closures it is never more certain than the plain filter.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "ConstantScan.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/sim/Geometry.h"
#include "urbanslam/slam/GlobalSlam.h"
#include "urbanslam/slam/KeyframeNodes.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/MapFile.h"

using namespace urbanslam;
using esdf::Mat3;
using esdf::Vec3;

namespace {

constexpr size_t kChain = 30;  // keyframes 0..kChain-1 of the first pass
constexpr size_t kPer = slam::KeyframeNodes::kKeyframesPerPose;

// The odometry of the chain: a curving drive, each step a metre.
Vec3 step(size_t k) { return {1.0, 0.05 * std::sin(0.3 * static_cast<double>(k)), 0.04 * std::cos(0.2 * static_cast<double>(k))}; }
Mat3 stepOmega() { return Vec3(1 / 0.01, 1 / 0.02, 1 / 1e-4).asDiagonal(); }

// Keyframes 0..kChain-1 in `filter` through `nodes`, each from the one before: the first
// `own_first` (at least one) poses of their own, then every kPer-th.
void chain(esdf::Esdf& filter, slam::KeyframeNodes& nodes, size_t own_first = 1) {
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-9);
  nodes.addFirst();
  own_first = std::max<size_t>(own_first, 1);
  for (size_t k = 1; k < kChain; ++k) {
    const bool own = k < own_first || (k - (own_first - 1)) % kPer == 0;
    EXPECT_EQ(nodes.add(k - 1, step(k), stepOmega()), own) << k;
    EXPECT_EQ(nodes.hung(k), !own) << k;
  }
}

// The same chain as poses 0..kChain-1 of a plain filter, each step's information times `share`.
void chain(esdf::Esdf& filter, double share = 1.0) {
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-9);
  for (size_t k = 1; k < kChain; ++k) filter.augmentRelative(static_cast<int>(k - 1), step(k), share * stepOmega());
}

void expectNear(const Mat3& a, const Mat3& b, double tol) { EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tol) << "\n" << a << "\n\n" << b; }

// reduced - exact is positive semi-definite (to rounding).
void expectAtLeast(const Mat3& reduced, const Mat3& exact, const std::string& what) {
  const double scale = exact.diagonal().maxCoeff();
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat3>(reduced - exact).eigenvalues().minCoeff(), -1e-9 * scale) << what;
}

}  // namespace

// Every kPer-th keyframe is a pose of the filter, the ones between hang from it; with no
// closure that is the chain with its inner poses marginalised out and the links' information
// times 1 - kReserved: the poses' means and marginal covariances are those of a plain chain
// whose steps have that share of their information, every keyframe's mean is the plain chain's,
// and every marginal and relative covariance lies between the plain chain's and the weakened
// one's (offsets taken as independent of each other and of the links can only widen them).
TEST(KeyframeNodes, AChainIsThePlainChainWithItsInnerPosesMarginalised) {
  esdf::Esdf reduced_filter, plain, weakened;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(plain);
  chain(weakened, 1 - slam::KeyframeNodes::kReserved);
  ASSERT_EQ(nodes.size(), kChain);
  EXPECT_EQ(nodes.nodes(), static_cast<int>((kChain + kPer - 1) / kPer));
  EXPECT_EQ(nodes.tailSize(), (kChain - 1) % kPer);
  for (size_t k = 0; k < kChain; ++k) {
    EXPECT_EQ(nodes.hung(k), k % kPer != 0) << k;
    EXPECT_EQ(nodes.node(k), static_cast<int>(k / kPer)) << k;
  }
  reduced_filter.recover();
  plain.recover();
  weakened.recover();
  const auto mode = esdf::CovarianceMode::Exact;
  for (size_t k = 0; k < kChain; ++k) {
    const int K = static_cast<int>(k);
    EXPECT_LE((nodes.mean(k) - plain.mean(K)).norm(), 1e-9) << k;
    const Mat3 c = nodes.marginalCovariance(k, mode);
    if (!nodes.hung(k)) expectNear(c, weakened.marginalCovariance(K, mode), 1e-9);
    expectAtLeast(c, plain.marginalCovariance(K, mode), "marginal " + std::to_string(k));
    expectAtLeast(weakened.marginalCovariance(K, mode), c, "weakened marginal " + std::to_string(k));
  }
  for (auto [i, k] : {std::pair<size_t, size_t>{4, 13}, {8, 9}, {0, 29}, {12, 27}, {13, 14}, {5, 7}, {6, 17}, {13, 24}}) {
    const int I = static_cast<int>(i), K = static_cast<int>(k);
    expectAtLeast(nodes.relativeCovariance(i, k, mode), plain.relativeCovariance(I, K, mode),
                  "relative " + std::to_string(i) + "-" + std::to_string(k));
  }
}

// With the first keyframes kept as poses of their own (a memory budget spent on them first),
// those are the plain chain's poses exactly, and from there on one keyframe in kPer is a pose.
TEST(KeyframeNodes, TheFirstKeyframesArePosesOfTheirOwn) {
  constexpr size_t kOwn = 12;
  esdf::Esdf reduced_filter, plain;
  slam::KeyframeNodes nodes(reduced_filter, true, kOwn);
  chain(reduced_filter, nodes, kOwn);
  chain(plain);
  EXPECT_EQ(nodes.nodes(), static_cast<int>(kOwn + (kChain - kOwn) / kPer));
  reduced_filter.recover();
  plain.recover();
  const auto mode = esdf::CovarianceMode::Exact;
  for (size_t k = 0; k < kChain; ++k) {
    const int K = static_cast<int>(k);
    EXPECT_LE((nodes.mean(k) - plain.mean(K)).norm(), 1e-9) << k;
    if (k < kOwn) {
      EXPECT_EQ(nodes.node(k), K);
      expectNear(nodes.marginalCovariance(k, mode), plain.marginalCovariance(K, mode), 1e-12);
    }
  }
}

// A second pass over the first pass's places, closed at every keyframe to the keyframe of the
// first pass beside it and to the nearest one with a pose of its own, against a filter in which every keyframe is a pose
// of its own and every closure goes in once: that filter holds each measurement exactly once,
// so its covariances are what the measurements allow, and a reduction that reuses no
// measurement unaccounted for is never more certain: reduced minus full is positive
// semi-definite for every keyframe's marginal and for relative poses across the passes. The
// pass still informs: the first pass's poses across it are known better than by their chain
// alone. Closures vaguer than a step, as in a city (a closure's position variance is 36 times a
// step's there, median).
TEST(KeyframeNodes, AReducedPassIsNeverMoreCertainThanEveryPose) {
  esdf::Esdf reduced_filter, full, first_only;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  chain(first_only);
  std::vector<Vec3> truth{Vec3::Zero()};
  for (size_t k = 1; k < kChain; ++k) truth.push_back(esdf::compose(truth.back(), step(k)));
  // The pass: 0.4 m to the left of keyframes 2.., heading alike.
  const Vec3 aside(0, 0.4, 0);
  const auto pass = [&](size_t k) { return esdf::compose(truth[k - kChain + 2], aside); };
  const size_t last = kChain + 21;
  const Mat3 return_omega = Vec3(1 / 1.0, 1 / 1.0, 1 / 0.05).asDiagonal();  // a vague way back
  const Mat3 closure_cov = Vec3(0.05, 0.05, 5e-4).asDiagonal();
  for (size_t k = kChain; k <= last; ++k) {
    const Vec3 prev = k == kChain ? truth[kChain - 1] : pass(k - 1);
    const Vec3 z = esdf::between(prev, pass(k));
    const Mat3& omega = k == kChain ? return_omega : stepOmega();
    nodes.add(k - 1, z, omega);
    full.augmentRelative(static_cast<int>(k - 1), z, omega);
    // The keyframe beside it (hung or not) and the nearest with a pose of its own.
    const size_t beside = k - kChain + 2, own = (beside + kPer / 2) / kPer * kPer;
    for (const size_t e : {beside, own}) {
      if (e == beside && e == own && k % 2 == 0) continue;
      const Vec3 c = esdf::between(truth[e], pass(k));
      const int before = reduced_filter.size();
      EXPECT_TRUE(nodes.observeRelative(e, k, c, closure_cov.inverse(), true).accepted) << k;
      EXPECT_TRUE(full.observeRelative(static_cast<int>(e), static_cast<int>(k), c, closure_cov.inverse(), true).accepted) << k;
      EXPECT_EQ(reduced_filter.size(), before);
    }
  }
  EXPECT_EQ(reduced_filter.size(), static_cast<int>((last + kPer) / kPer));
  reduced_filter.recover();
  full.recover();
  for (size_t k = 0; k <= last; ++k) EXPECT_LE((nodes.mean(k) - (k < kChain ? truth[k] : pass(k))).norm(), 1e-6) << k;
  const auto mode = esdf::CovarianceMode::Exact;
  for (size_t k = 0; k <= last; ++k)
    expectAtLeast(nodes.marginalCovariance(k, mode), full.marginalCovariance(static_cast<int>(k), mode), "marginal " + std::to_string(k));
  for (auto [i, k] : {std::pair<size_t, size_t>{2, 14}, {3, 9}, {0, kChain - 1}, {5, kChain + 4}, {kChain + 3, last}, {kChain, kChain + 1},
                      {8, kChain + 7}, {kChain + 5, kChain + 6}})
    expectAtLeast(nodes.relativeCovariance(i, k, mode), full.relativeCovariance(static_cast<int>(i), static_cast<int>(k), mode),
                  "relative " + std::to_string(i) + "-" + std::to_string(k));
  const Mat3 across = nodes.relativeCovariance(4, 20, mode), alone = first_only.relativeCovariance(4, 20, mode);
  EXPECT_LT(across(0, 0) + across(1, 1), 0.9 * (alone(0, 0) + alone(1, 1)));
}

// A closure of a hung keyframe goes into the filter between the two poses (no pose added), and
// moves the map as the full filter's does, by less: it takes its offset with a share of its
// information.
TEST(KeyframeNodes, AClosureOfAHungKeyframeMovesTheMapTheWayTheFullFilterDoes) {
  esdf::Esdf reduced_filter, full;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  ASSERT_TRUE(nodes.hung(kChain - 1));
  reduced_filter.recover();
  full.recover();
  std::vector<Vec3> before;
  for (size_t k = 0; k < kChain; ++k) before.push_back(full.mean(static_cast<int>(k)));
  // Keyframe kChain-1 (hung) sees keyframe 4 2 cm and 0.5° off where the chain has it.
  const Vec3 z = esdf::between(full.mean(static_cast<int>(kChain - 1)), full.mean(4)) + Vec3(0.02, -0.02, 0.5 * M_PI / 180);
  const Mat3 omega = Vec3(1 / 0.0004, 1 / 0.0004, 1 / 3e-5).asDiagonal();
  const int poses = reduced_filter.size();
  EXPECT_TRUE(nodes.observeRelative(kChain - 1, 4, z, omega, true).accepted);
  EXPECT_TRUE(full.observeRelative(static_cast<int>(kChain - 1), 4, z, omega, true).accepted);
  EXPECT_EQ(reduced_filter.size(), poses);
  reduced_filter.recover();
  full.recover();
  double dot = 0, full_norm2 = 0, reduced_norm2 = 0;
  for (size_t k = 0; k < kChain; ++k) {
    const Eigen::Vector2d f = (full.mean(static_cast<int>(k)) - before[k]).head<2>(), r = (nodes.mean(k) - before[k]).head<2>();
    dot += f.dot(r);
    full_norm2 += f.squaredNorm();
    reduced_norm2 += r.squaredNorm();
  }
  EXPECT_GE(std::sqrt(full_norm2), 5e-3);
  EXPECT_GE(dot / std::sqrt(full_norm2 * reduced_norm2), 0.95);  // the same direction
  EXPECT_GE(std::sqrt(reduced_norm2), 0.3 * std::sqrt(full_norm2));
  EXPECT_LE(std::sqrt(reduced_norm2), 1.05 * std::sqrt(full_norm2));
  // Each closure through the group's offsets takes half the share of the one before: five more
  // go in, and the seventh would take the offset with more than kMaxOffsetScale times its
  // covariance: gated, it adds nothing.
  for (const int e : {8, 12, 16, 20, 24})
    EXPECT_TRUE(nodes.observeRelative(kChain - 1, static_cast<size_t>(e), esdf::between(nodes.mean(kChain - 1), nodes.mean(static_cast<size_t>(e))),
                                      omega, true)
                    .accepted);
  reduced_filter.recover();
  const Vec3 kept = reduced_filter.mean(3);
  const Vec3 off = esdf::between(nodes.mean(kChain - 1), nodes.mean(12)) + Vec3(0.02, 0.02, 0);
  EXPECT_TRUE(nodes.observeRelative(kChain - 1, 12, off, omega, true).accepted);
  reduced_filter.recover();
  EXPECT_LE((reduced_filter.mean(3) - kept).norm(), 1e-12);
}

// Many tight closures of one hung keyframe: each would pin its filter pose through the same
// offset, whose steps the plain filter counts once. Shared out (the first through a group's
// offsets takes 1/20 of their information, the next 1/40, ...), the pose is never more certain
// than in the plain filter with every closure.
TEST(KeyframeNodes, ClosuresThroughOneOffsetCountItsStepsOnce) {
  esdf::Esdf reduced_filter, full;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  const size_t k = kChain - 1;  // hangs a step from kChain - 2
  ASSERT_TRUE(nodes.hung(k));
  const Mat3 tight = Vec3(1e8, 1e8, 1e10).asDiagonal();
  for (const int e : {0, 4, 8, 12, 16}) {
    const Vec3 z = esdf::between(full.mean(e), full.mean(static_cast<int>(k)));
    EXPECT_TRUE(nodes.observeRelative(static_cast<size_t>(e), k, z, tight, true).accepted);
    EXPECT_TRUE(full.observeRelative(e, static_cast<int>(k), z, tight, true).accepted);
  }
  reduced_filter.recover();
  full.recover();
  const auto mode = esdf::CovarianceMode::Exact;
  expectAtLeast(nodes.marginalCovariance(kChain - 2, mode), full.marginalCovariance(kChain - 2, mode), "the pose it hangs from");
  expectAtLeast(nodes.relativeCovariance(0, kChain - 2, mode), full.relativeCovariance(0, kChain - 2, mode), "relative to the first");
}

TEST(KeyframeNodes, ReadBackHangsTheSame) {
  esdf::Esdf reduced_filter;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  ASSERT_GT(nodes.tailSize(), 0u);
  EXPECT_TRUE(nodes.observeRelative(kChain - 1, 8, esdf::between(nodes.mean(kChain - 1), nodes.mean(8)), stepOmega(), true).accepted);
  common::BinaryWriter w;
  reduced_filter.writeState(w);
  nodes.writeState(w);
  const std::string bytes = w.take();
  common::BinaryReader r(bytes.data(), bytes.size(), "test");
  esdf::Esdf filter;
  slam::KeyframeNodes back(filter, true);
  filter.readState(r);
  back.readState(r, kChain, slam::kMapFormatVersion);
  r.expectEnd();
  for (size_t k = 0; k < kChain; ++k) {
    EXPECT_EQ(back.node(k), nodes.node(k));
    EXPECT_EQ(back.mean(k), nodes.mean(k));
  }
  EXPECT_EQ(back.tailSize(), nodes.tailSize());
  // The next keyframes hang and link as they would have (the closure's doubled offset included).
  for (size_t k = kChain; k < kChain + kPer; ++k) {
    EXPECT_EQ(back.add(k - 1, step(k), stepOmega()), nodes.add(k - 1, step(k), stepOmega()));
    EXPECT_EQ(back.mean(k), nodes.mean(k));
  }
  // And a closure through the offsets takes the same share (the closures counted per group).
  ASSERT_TRUE(nodes.hung(kChain + 1));
  const Vec3 z = esdf::between(nodes.mean(kChain + 1), nodes.mean(12)) + Vec3(0.02, -0.01, 0.002);
  EXPECT_TRUE(back.observeRelative(kChain + 1, 12, z, stepOmega(), true).accepted);
  EXPECT_TRUE(nodes.observeRelative(kChain + 1, 12, z, stepOmega(), true).accepted);
  filter.recover();
  reduced_filter.recover();
  for (size_t k = 0; k < kChain + kPer; ++k) EXPECT_EQ(back.mean(k), nodes.mean(k)) << k;
  EXPECT_EQ(filter.marginalCovariance(filter.size() - 1, esdf::CovarianceMode::Exact),
            reduced_filter.marginalCovariance(reduced_filter.size() - 1, esdf::CovarianceMode::Exact));
  // A map without reduction is refused by a reader with it, and the other way round; so is
  // a reduced graph of map format 10, which hung keyframes otherwise.
  for (const std::uint32_t version : {slam::kMapFormatVersion, std::uint32_t{10}}) {
    common::BinaryReader again(bytes.data(), bytes.size(), "test");
    esdf::Esdf other;
    slam::KeyframeNodes reader(other, version == 10);
    other.readState(again);
    EXPECT_THROW(reader.readState(again, kChain, version), common::InputError) << version;
  }
}

namespace {

// A front 180° scan from (x, 0) heading along a corridor: walls at y = ±4 with posts 0.6 m deep
// at irregular places along them, so an alignment measures where along the corridor it is.
io::LaserScan corridorScan(double timestamp, double x) {
  std::vector<sim::Segment> walls{{{-50, -4}, {400, -4}}, {{-50, 4}, {400, 4}}};
  for (int i = 0; i < 120; ++i) {
    const double px = -40 + 3.7 * i + 0.6 * ((i * i) % 5);
    const double side = i % 2 == 0 ? -4 : 4;
    walls.push_back({{px, side}, {px, side - 0.6 * (side > 0 ? 1 : -1)}});
  }
  io::LaserScan s = test::constantScan(timestamp, 0.0f, 30.0);
  for (size_t b = 0; b < s.ranges.size(); ++b) {
    const double a = s.angle_min_rad + static_cast<double>(b) * s.angle_increment_rad;
    double t = sim::kNoHit;
    for (const auto& w : walls) t = std::min(t, sim::raySegment({x, 0}, {std::cos(a), std::sin(a)}, w));
    s.valid[b] = t < s.max_range_m;
    s.ranges[b] = static_cast<float>(s.valid[b] ? t : s.max_range_m);
  }
  return s;
}

}  // namespace

// Global SLAM over a revisit: keyframes 0-199 a metre apart along a corridor, then from keyframe
// 200 the same places from x = 100 on again (the alignments measure the true relative poses).
// Without reduction each keyframe is a filter pose of its own; with it one in kPer is, the
// revisit closes as often, and its keyframes stay where the first pass put the places.
TEST(KeyframeNodes, ARevisitAddsInformationNotPoses) {
  const auto run = [](bool reduced) {
    struct Out {
      slam::PipelineOptions options;
      slam::PipelineStats stats;
      std::vector<slam::PipelineObserver*> observers;
      std::unique_ptr<slam::Map> map;
      std::unique_ptr<slam::GlobalSlam> global;
    };
    auto o = std::make_unique<Out>();
    o->options.loop_closure.detector = slam::LoopClosureOptions::Detector::None;
    o->options.loop_closure.submap_check_path_m = 0;
    o->options.estimator.reduced_pose_graph = reduced;
    o->map = std::make_unique<slam::Map>(std::make_unique<esdf::Esdf>(), 2.0, io::ScanStore::kDefaultCacheBytes, "", reduced);
    o->global = std::make_unique<slam::GlobalSlam>(o->options, *o->map, o->stats, o->observers);
    slam::KeyframeConstraint c;
    c.cov = Eigen::Vector3d(0.01, 0.01, 1e-6).asDiagonal();
    for (size_t k = 0; k <= 260; ++k) {
      c.z = {k == 200 ? -99.0 : 1.0, 0, 0};
      const double x = k < 200 ? static_cast<double>(k) : static_cast<double>(k) - 100;
      o->global->addKeyframe({k, static_cast<double>(k), {}, true, false, {}}, io::CompactScan(corridorScan(k, x)), c);
      o->global->closeLoops(k, std::chrono::steady_clock::now());
    }
    o->global->finish();
    return o;
  };
  const auto plain = run(false), reduced = run(true);
  ASSERT_GE(plain->stats.closures_accepted, 40u);
  EXPECT_EQ(plain->map->filter()->size(), 261);
  EXPECT_GE(reduced->stats.closures_accepted, 40u);
  EXPECT_LE(reduced->map->filter()->size(), 261 / static_cast<int>(kPer) + 1);
  size_t hung = 0;
  for (size_t k = 200; k <= 260; ++k) hung += reduced->map->nodes()->hung(k) ? 1 : 0;
  EXPECT_GE(hung, 61 * (kPer - 1) / kPer - 1);
  for (size_t k = 200; k <= 260; ++k) {
    const common::Pose2 a = reduced->map->keyframes()[k].pose, b = plain->map->keyframes()[k].pose;
    EXPECT_NEAR(a.x, b.x, 0.05) << k;
    EXPECT_NEAR(a.y, b.y, 0.05) << k;
    EXPECT_NEAR(a.x, static_cast<double>(k) - 100, 0.1) << k;
  }
}

// The early gate the loop closer asks before its costly tests: for keyframes that are filter
// poses, hung from two of them, or hung from one, a refusal it gives is the gate's own (the same
// d^2), and it gives none for a closure the gate admits.
TEST(KeyframeNodes, AnEarlyRefusalIsTheGatesOwnForHungKeyframesToo) {
  esdf::Esdf filter;
  slam::KeyframeNodes nodes(filter, true);
  chain(filter, nodes);
  filter.recover();
  // Three keyframes more, the last a filter pose: the factor is stale again, so the gate's exact
  // covariance would take a factorisation.
  for (size_t k = kChain; k < kChain + 3; ++k) nodes.add(k - 1, step(k), stepOmega());
  const Mat3 omega = Vec3(1 / 0.0004, 1 / 0.0004, 1 / 3e-5).asDiagonal();
  // Filter poses 0 and 8; 4 and the hung kChain; 25 and 27, both hung from 24.
  const std::vector<std::pair<size_t, size_t>> pairs{{0, 8}, {4, kChain}, {25, 27}};
  ASSERT_FALSE(nodes.hung(0) || nodes.hung(8) || nodes.hung(4));
  ASSERT_TRUE(nodes.hung(kChain) && nodes.hung(25) && nodes.hung(27));
  int refused = 0;
  for (const auto& [i, k] : pairs)
    for (const double off : {0.0, 3.0}) {
      const Vec3 z = esdf::between(nodes.mean(i), nodes.mean(k)) + Vec3(off, -off, 0);
      const std::optional<esdf::GateResult> early = nodes.refusalWithoutFactorising(i, k, z, omega);
      const esdf::GateResult full = nodes.gateRelative(i, k, z, omega);
      EXPECT_EQ(full.accepted, off == 0.0) << i << " " << k;
      if (off == 0.0) {
        EXPECT_FALSE(early) << i << " " << k;
      }
      if (!early) continue;
      ++refused;
      EXPECT_FALSE(early->accepted);
      EXPECT_NEAR(early->mahalanobis2, full.mahalanobis2, 1e-9 * full.mahalanobis2) << i << " " << k;
    }
  EXPECT_EQ(refused, 3);  // 3 m off, each kind is refused without a factorisation
}
