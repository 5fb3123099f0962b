// Keyframes hung from the filter poses of others (a reduced pose graph), against plain filters
// in which every keyframe is a pose of its own and every measurement goes in once: a drive over
// new ground is that filter, and a pass over mapped ground, hung from the earlier visit's poses,
// is never more certain than it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <functional>
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

// Keyframes 0..kChain-1 in `filter` through `nodes`, each from the one before: new ground, so
// every one a pose of its own.
void chain(esdf::Esdf& filter, slam::KeyframeNodes& nodes) {
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-9);
  nodes.addFirst();
  for (size_t k = 1; k < kChain; ++k) EXPECT_TRUE(nodes.add(k - 1, step(k), stepOmega())) << k;
}

// The same chain as poses 0..kChain-1 of a plain filter.
void chain(esdf::Esdf& filter) {
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-9);
  for (size_t k = 1; k < kChain; ++k) filter.augmentRelative(static_cast<int>(k - 1), step(k), stepOmega());
}

// The next keyframe in both: `nodes`' and the plain filter `full`'s, from the newest.
bool addBoth(slam::KeyframeNodes& nodes, esdf::Esdf& full, const Vec3& z, const Mat3& omega) {
  full.augmentRelative(full.size() - 1, z, omega);
  return nodes.add(nodes.size() - 1, z, omega);
}

void expectNear(const Mat3& a, const Mat3& b, double tol) { EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tol) << "\n" << a << "\n\n" << b; }

// reduced - exact is positive semi-definite (to rounding).
void expectAtLeast(const Mat3& reduced, const Mat3& exact, const std::string& what) {
  const double scale = exact.diagonal().maxCoeff();
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat3>(reduced - exact).eigenvalues().minCoeff(), -1e-9 * scale) << what;
}

const Mat3 kCloseOmega = Vec3(1 / 0.0004, 1 / 0.0004, 1 / 3e-5).asDiagonal();

}  // namespace

// New ground: with no closure every keyframe is a pose of its own, and the filter is the plain
// chain's.
TEST(KeyframeNodes, NewGroundIsEveryKeyframeAPoseOfItsOwn) {
  esdf::Esdf reduced_filter, plain;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(plain);
  ASSERT_EQ(nodes.size(), kChain);
  EXPECT_EQ(nodes.nodes(), static_cast<int>(kChain));
  EXPECT_EQ(nodes.tailSize(), 0u);
  reduced_filter.recover();
  plain.recover();
  for (size_t k = 0; k < kChain; ++k) {
    EXPECT_FALSE(nodes.hung(k)) << k;
    EXPECT_EQ(nodes.node(k), static_cast<int>(k));
    EXPECT_LE((nodes.mean(k) - plain.mean(static_cast<int>(k))).norm(), 1e-12) << k;
    expectNear(nodes.marginalCovariance(k, esdf::CovarianceMode::Exact), plain.marginalCovariance(static_cast<int>(k)), 1e-12);
  }
}

// A second pass over the first pass's places, closed at every keyframe to the keyframe of the
// first pass beside it (and, every other keyframe, to the one after that), against a filter in
// which every keyframe is a pose of its own and every closure goes in once: that filter holds
// each measurement exactly once, so its covariances are what the measurements allow, and a
// reduction that reuses no measurement unaccounted for is never more certain: reduced minus
// full is positive semi-definite for every keyframe's marginal and for relative poses across
// the passes. The pass adds one pose (where it arrives, before its first closure) and hangs
// from the first pass's poses from then on; it still informs them. Closures vaguer than a step,
// as in a city (a closure's position variance is 36 times a step's there, median).
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
    EXPECT_EQ(addBoth(nodes, full, z, omega), k == kChain) << k;
    const size_t beside = k - kChain + 2;
    for (const size_t e : {beside, beside + 1}) {
      if (e != beside && k % 2 == 0) continue;
      const Vec3 c = esdf::between(truth[e], pass(k));
      const int before = reduced_filter.size();
      EXPECT_TRUE(nodes.observeRelative(e, k, c, closure_cov.inverse(), true).accepted) << k;
      EXPECT_TRUE(full.observeRelative(static_cast<int>(e), static_cast<int>(k), c, closure_cov.inverse(), true).accepted) << k;
      EXPECT_EQ(reduced_filter.size(), before);
    }
  }
  EXPECT_EQ(reduced_filter.size(), static_cast<int>(kChain + 1));
  reduced_filter.recover();
  full.recover();
  for (size_t k = 0; k <= last; ++k) EXPECT_LE((nodes.mean(k) - (k < kChain ? truth[k] : pass(k))).norm(), 1e-6) << k;
  const auto mode = esdf::CovarianceMode::Exact;
  for (size_t k = 0; k <= last; ++k)
    expectAtLeast(nodes.marginalCovariance(k, mode), full.marginalCovariance(static_cast<int>(k), mode), "marginal " + std::to_string(k));
  for (auto [i, k] : {std::pair<size_t, size_t>{2, 14},
                      {3, 9},
                      {0, kChain - 1},
                      {5, kChain + 4},
                      {kChain + 3, last},
                      {kChain, kChain + 1},
                      {8, kChain + 7},
                      {kChain + 5, kChain + 6},
                      {kChain + 4, kChain + 5}})
    expectAtLeast(nodes.relativeCovariance(i, k, mode), full.relativeCovariance(static_cast<int>(i), static_cast<int>(k), mode),
                  "relative " + std::to_string(i) + "-" + std::to_string(k));
  const Mat3 across = nodes.relativeCovariance(4, 20, mode), alone = first_only.relativeCovariance(4, 20, mode);
  EXPECT_LT(across(0, 0) + across(1, 1), 0.99 * (alone(0, 0) + alone(1, 1)));
}

// A third pass closed at every keyframe to the second pass's keyframe beside it, which hangs
// (through its offsets, with their shares), and every other keyframe to the first pass's: it
// re-roots at the first pass's poses only, adds no pose, and is never more certain than the
// filter with every pose.
TEST(KeyframeNodes, AThirdPassHangsFromTheFirstPassesPoses) {
  esdf::Esdf reduced_filter, full;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  std::vector<Vec3> truth{Vec3::Zero()};
  for (size_t k = 1; k < kChain; ++k) truth.push_back(esdf::compose(truth.back(), step(k)));
  const Mat3 return_omega = Vec3(1 / 1.0, 1 / 1.0, 1 / 0.05).asDiagonal();
  const Mat3 closure_omega = Vec3(1 / 0.05, 1 / 0.05, 1 / 5e-4).asDiagonal().toDenseMatrix();
  std::vector<Vec3> poses(truth);
  // A pass of `n` keyframes from keyframe `first` of the first pass on, `side` m to its left,
  // each closed to the keyframes `closed_to(k)` (of earlier passes).
  const auto drive = [&](size_t first, size_t n, double side, const std::function<std::vector<size_t>(size_t)>& closed_to) {
    const size_t start = nodes.size();
    for (size_t j = 0; j < n; ++j) {
      const size_t k = start + j;
      const Vec3 p = esdf::compose(truth[first + j], Vec3(0, side, 0));
      // The second pass arrives from a pose of its own, the third from the second's last
      // keyframe, whose closure re-rooted.
      EXPECT_EQ(addBoth(nodes, full, esdf::between(poses.back(), p), j == 0 ? return_omega : stepOmega()), j == 0 && k == kChain) << k;
      poses.push_back(p);
      for (const size_t e : closed_to(k)) {
        const Vec3 c = esdf::between(poses[e], p);
        EXPECT_TRUE(nodes.observeRelative(e, k, c, closure_omega, true).accepted) << k;
        EXPECT_TRUE(full.observeRelative(static_cast<int>(e), static_cast<int>(k), c, closure_omega, true).accepted) << k;
      }
    }
    return start;
  };
  const size_t second = drive(2, 20, 0.4, [&](size_t k) { return std::vector<size_t>{k - kChain + 2}; });
  const int after_second = reduced_filter.size();
  const size_t third = drive(4, 16, -0.4, [&](size_t k) {
    const size_t j = k - (second + 20);
    std::vector<size_t> to{second + j + 2};
    if (j % 2 == 0) to.push_back(j + 4);
    return to;
  });
  EXPECT_EQ(after_second, static_cast<int>(kChain + 1));
  EXPECT_EQ(reduced_filter.size(), after_second);
  for (size_t k = third; k < nodes.size(); ++k) EXPECT_TRUE(nodes.hung(k)) << k;
  reduced_filter.recover();
  full.recover();
  const auto mode = esdf::CovarianceMode::Exact;
  for (size_t k = 0; k < nodes.size(); ++k) {
    EXPECT_LE((nodes.mean(k) - poses[k]).norm(), 1e-6) << k;
    expectAtLeast(nodes.marginalCovariance(k, mode), full.marginalCovariance(static_cast<int>(k), mode), "marginal " + std::to_string(k));
  }
  for (auto [i, k] : {std::pair<size_t, size_t>{3, third + 5},
                      {second + 4, third + 5},
                      {third + 2, third + 3},
                      {third + 1, third + 12},
                      {second + 7, third + 3},
                      {0, third + 15}})
    expectAtLeast(nodes.relativeCovariance(i, k, mode), full.relativeCovariance(static_cast<int>(i), static_cast<int>(k), mode),
                  "relative " + std::to_string(i) + "-" + std::to_string(k));
}

// The closure that re-roots moves the map as the full filter's does, by less (it goes in with
// half its information), and adds no pose; the next keyframes hang from the pose it closed to.
// Closures through a hung keyframe's offsets take halving shares of them: six go in, and the
// seventh would take the offsets with more than kMaxOffsetScale times their covariance: gated,
// it adds nothing.
TEST(KeyframeNodes, AReRootingClosureMovesTheMapTheWayTheFullFilterDoes) {
  esdf::Esdf reduced_filter, full;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  reduced_filter.recover();
  full.recover();
  std::vector<Vec3> before;
  for (size_t k = 0; k < kChain; ++k) before.push_back(full.mean(static_cast<int>(k)));
  // Keyframe kChain-1 sees keyframe 4 2 cm and 0.5° off where the chain has it.
  const Vec3 z = esdf::between(full.mean(4), full.mean(static_cast<int>(kChain - 1))) + Vec3(0.02, -0.02, 0.5 * M_PI / 180);
  const int poses = reduced_filter.size();
  EXPECT_TRUE(nodes.observeRelative(4, kChain - 1, z, kCloseOmega, true).accepted);
  EXPECT_TRUE(full.observeRelative(4, static_cast<int>(kChain - 1), z, kCloseOmega, true).accepted);
  EXPECT_EQ(reduced_filter.size(), poses);
  EXPECT_TRUE(nodes.rerooted());
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
  // The next two hang from keyframe 4's pose, at the closure's measurement and the steps.
  for (size_t k = kChain; k < kChain + 2; ++k) {
    EXPECT_FALSE(addBoth(nodes, full, step(k), stepOmega())) << k;
    EXPECT_TRUE(nodes.hung(k));
    EXPECT_EQ(nodes.node(k), 4);
  }
  EXPECT_EQ(reduced_filter.size(), poses);
  EXPECT_LE((nodes.mean(kChain + 1) - esdf::compose(esdf::compose(esdf::compose(nodes.mean(4), z), step(kChain)), step(kChain + 1))).norm(),
            1e-12);
  // Closures of keyframe kChain (no longer the newest) go through its group's offsets.
  for (const int e : {8, 12, 16, 20, 24, 10})
    EXPECT_TRUE(nodes
                    .observeRelative(static_cast<size_t>(e), kChain, esdf::between(nodes.mean(static_cast<size_t>(e)), nodes.mean(kChain)),
                                     kCloseOmega, true)
                    .accepted);
  reduced_filter.recover();
  const Vec3 kept = reduced_filter.mean(3);
  const Vec3 off = esdf::between(nodes.mean(12), nodes.mean(kChain)) + Vec3(0.02, 0.02, 0);
  EXPECT_TRUE(nodes.observeRelative(12, kChain, off, kCloseOmega, true).accepted);
  reduced_filter.recover();
  EXPECT_LE((reduced_filter.mean(3) - kept).norm(), 1e-12);
}

// Many tight closures of one hung keyframe: each would pin its filter pose through the same
// offsets (a tight re-rooting closure and tight steps), which the plain filter counts once.
// Shared out, the pose is never more certain than in the plain filter with every closure.
TEST(KeyframeNodes, ClosuresThroughOneOffsetCountItsStepsOnce) {
  esdf::Esdf reduced_filter, full;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  const Vec3 z = esdf::between(full.mean(10), full.mean(static_cast<int>(kChain - 1)));
  const Mat3 reroot = Vec3(1e6, 1e6, 1e8).asDiagonal(), tight_step = Vec3(1e7, 1e7, 1e9).asDiagonal();
  EXPECT_TRUE(nodes.observeRelative(10, kChain - 1, z, reroot, true).accepted);
  EXPECT_TRUE(full.observeRelative(10, static_cast<int>(kChain - 1), z, reroot, true).accepted);
  for (size_t k = kChain; k < kChain + 2; ++k) EXPECT_FALSE(addBoth(nodes, full, step(k), tight_step));
  const size_t k = kChain;  // hangs from keyframe 10's pose
  ASSERT_TRUE(nodes.hung(k));
  full.recover();
  const Mat3 tight = Vec3(1e8, 1e8, 1e10).asDiagonal();
  // Five closures to the first keyframe (anchored): in the plain filter keyframe 10 is no better
  // known than through the offsets once; five links through them, each at full weight, would
  // know it five times better.
  for (const int e : {0, 0, 0, 0, 0}) {
    const Vec3 c = esdf::between(full.mean(e), full.mean(static_cast<int>(k)));
    EXPECT_TRUE(nodes.observeRelative(static_cast<size_t>(e), k, c, tight, true).accepted);
    EXPECT_TRUE(full.observeRelative(e, static_cast<int>(k), c, tight, true).accepted);
  }
  reduced_filter.recover();
  full.recover();
  const auto mode = esdf::CovarianceMode::Exact;
  for (const size_t p : {size_t{10}, kChain - 1, kChain, kChain + 1})
    expectAtLeast(nodes.marginalCovariance(p, mode), full.marginalCovariance(static_cast<int>(p), mode), "marginal " + std::to_string(p));
  expectAtLeast(nodes.relativeCovariance(0, 10, mode), full.relativeCovariance(0, 10, mode), "10 relative to the first");
  expectAtLeast(nodes.relativeCovariance(0, k, mode), full.relativeCovariance(0, static_cast<int>(k), mode), "relative to the first");
}

// A re-rooting closure is in two measurements: the group's link to the pose it closed to, and
// the base the next keyframes hang at. When the next keyframe closes again (re-rooting at once,
// here to the keyframe before it), the two links between the same poses both hold the first
// closure: with half its information in each, the filter is never more certain than the plain
// one that holds it once.
TEST(KeyframeNodes, AReRootingClosureIsCountedOnce) {
  esdf::Esdf reduced_filter, full;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  chain(full);
  const Mat3 reroot = Vec3(1e6, 1e6, 1e8).asDiagonal(), tight = Vec3(1e8, 1e8, 1e10).asDiagonal();
  const Vec3 z = esdf::between(full.mean(10), full.mean(static_cast<int>(kChain - 1)));
  EXPECT_TRUE(nodes.observeRelative(10, kChain - 1, z, reroot, true).accepted);
  EXPECT_TRUE(full.observeRelative(10, static_cast<int>(kChain - 1), z, reroot, true).accepted);
  EXPECT_FALSE(addBoth(nodes, full, step(kChain), Vec3(1e7, 1e7, 1e9).asDiagonal()));
  const Vec3 back = step(kChain);
  EXPECT_TRUE(nodes.observeRelative(kChain - 1, kChain, back, tight, true).accepted);
  EXPECT_TRUE(full.observeRelative(static_cast<int>(kChain - 1), static_cast<int>(kChain), back, tight, true).accepted);
  EXPECT_TRUE(nodes.rerooted());
  reduced_filter.recover();
  full.recover();
  const auto mode = esdf::CovarianceMode::Exact;
  expectAtLeast(nodes.relativeCovariance(10, kChain - 1, mode), full.relativeCovariance(10, static_cast<int>(kChain - 1), mode),
                "the closure's two poses");
  expectAtLeast(nodes.marginalCovariance(kChain - 1, mode), full.marginalCovariance(static_cast<int>(kChain - 1), mode), "marginal");
}

// A later pass closed to the very pose its group hangs from: the closure measures the newest
// keyframe's offset, and is fused with it (no link, the group goes on): the keyframe is known
// better than before, never better than in the filter with every pose.
TEST(KeyframeNodes, AClosureToThePoseItsGroupHangsFromIsFusedWithItsOffset) {
  esdf::Esdf filter, full;
  slam::KeyframeNodes nodes(filter, true);
  chain(filter, nodes);
  chain(full);
  const Vec3 z0 = esdf::between(full.mean(10), full.mean(static_cast<int>(kChain - 1)));
  EXPECT_TRUE(nodes.observeRelative(10, kChain - 1, z0, kCloseOmega, true).accepted);
  EXPECT_TRUE(full.observeRelative(10, static_cast<int>(kChain - 1), z0, kCloseOmega, true).accepted);
  for (size_t k = kChain; k < kChain + 2; ++k) EXPECT_FALSE(addBoth(nodes, full, step(k), stepOmega()));
  const size_t factors = filter.factorCount();
  const auto mode = esdf::CovarianceMode::Exact;
  const Mat3 before = nodes.relativeCovariance(10, kChain + 1, mode);
  const Vec3 z = esdf::between(nodes.mean(10), nodes.mean(kChain + 1)) + Vec3(0.01, 0, 0);
  EXPECT_TRUE(nodes.observeRelative(10, kChain + 1, z, kCloseOmega, true).accepted);
  EXPECT_TRUE(full.observeRelative(10, static_cast<int>(kChain + 1), z, kCloseOmega, true).accepted);
  EXPECT_EQ(filter.factorCount(), factors);
  EXPECT_FALSE(nodes.rerooted());
  const Mat3 after = nodes.relativeCovariance(10, kChain + 1, mode);
  EXPECT_LT(after(0, 0), 0.5 * before(0, 0));
  // Moved towards the closure by the share its information has.
  const double moved = esdf::between(nodes.mean(10), nodes.mean(kChain + 1)).x() - (z.x() - 0.01);
  EXPECT_GT(moved, 0.002);
  EXPECT_LT(moved, 0.01);
  filter.recover();
  full.recover();
  expectAtLeast(nodes.relativeCovariance(10, kChain + 1, mode), full.relativeCovariance(10, static_cast<int>(kChain + 1), mode),
                "relative");
  expectAtLeast(nodes.marginalCovariance(kChain + 1, mode), full.marginalCovariance(static_cast<int>(kChain + 1), mode), "marginal");
  // The group goes on: one more keyframe hangs, the next is a pose of its own.
  EXPECT_FALSE(nodes.add(kChain + 1, step(kChain + 2), stepOmega()));
  EXPECT_TRUE(nodes.add(kChain + 2, step(kChain + 3), stepOmega()));
}

namespace {

// `nodes` and its filter written and read back into `filter` and `back`.
void readBack(const esdf::Esdf& written_filter, const slam::KeyframeNodes& written, esdf::Esdf& filter, slam::KeyframeNodes& back,
              std::string* bytes = nullptr) {
  common::BinaryWriter w;
  written_filter.writeState(w);
  written.writeState(w);
  const std::string b = w.take();
  common::BinaryReader r(b.data(), b.size(), "test");
  filter.readState(r);
  back.readState(r, written.size(), slam::kMapFormatVersion);
  r.expectEnd();
  if (bytes) *bytes = b;
}

}  // namespace

TEST(KeyframeNodes, ReadBackHangsTheSame) {
  esdf::Esdf reduced_filter;
  slam::KeyframeNodes nodes(reduced_filter, true);
  chain(reduced_filter, nodes);
  EXPECT_TRUE(nodes.observeRelative(8, kChain - 1, esdf::between(nodes.mean(8), nodes.mean(kChain - 1)), stepOmega(), true).accepted);
  // Read back between the re-rooting closure and the keyframe that hangs at it.
  esdf::Esdf filter0;
  slam::KeyframeNodes back0(filter0, true);
  readBack(reduced_filter, nodes, filter0, back0);
  EXPECT_TRUE(back0.rerooted());
  for (size_t k = kChain; k < kChain + 2; ++k) {
    EXPECT_FALSE(back0.add(k - 1, step(k), stepOmega()));
    EXPECT_FALSE(nodes.add(k - 1, step(k), stepOmega()));
    EXPECT_EQ(back0.mean(k), nodes.mean(k));
  }
  // A closure through the group's offsets, then read back again.
  EXPECT_TRUE(nodes.observeRelative(12, kChain, esdf::between(nodes.mean(12), nodes.mean(kChain)), stepOmega(), true).accepted);
  esdf::Esdf filter;
  slam::KeyframeNodes back(filter, true);
  std::string bytes;
  readBack(reduced_filter, nodes, filter, back, &bytes);
  for (size_t k = 0; k < nodes.size(); ++k) {
    EXPECT_EQ(back.node(k), nodes.node(k));
    EXPECT_EQ(back.mean(k), nodes.mean(k));
  }
  EXPECT_EQ(back.tailSize(), nodes.tailSize());
  // The next keyframes hang and link as they would have.
  for (size_t k = kChain + 2; k < kChain + 2 + kPer; ++k) {
    EXPECT_EQ(back.add(k - 1, step(k), stepOmega()), nodes.add(k - 1, step(k), stepOmega()));
    EXPECT_EQ(back.mean(k), nodes.mean(k));
  }
  // And a closure through the offsets takes the same share (the closures counted per group).
  ASSERT_TRUE(nodes.hung(kChain + 1));
  const Vec3 z = esdf::between(nodes.mean(12), nodes.mean(kChain + 1)) + Vec3(0.02, -0.01, 0.002);
  EXPECT_TRUE(back.observeRelative(12, kChain + 1, z, stepOmega(), true).accepted);
  EXPECT_TRUE(nodes.observeRelative(12, kChain + 1, z, stepOmega(), true).accepted);
  filter.recover();
  reduced_filter.recover();
  for (size_t k = 0; k < nodes.size(); ++k) EXPECT_EQ(back.mean(k), nodes.mean(k)) << k;
  EXPECT_EQ(filter.marginalCovariance(filter.size() - 1, esdf::CovarianceMode::Exact),
            reduced_filter.marginalCovariance(reduced_filter.size() - 1, esdf::CovarianceMode::Exact));
  // A map without reduction is refused by a reader with it, and the other way round; so is
  // a reduced graph of map format 10, which hung keyframes otherwise.
  for (const std::uint32_t version : {slam::kMapFormatVersion, std::uint32_t{10}}) {
    common::BinaryReader again(bytes.data(), bytes.size(), "test");
    esdf::Esdf other;
    slam::KeyframeNodes reader(other, version == 10);
    other.readState(again);
    EXPECT_THROW(reader.readState(again, nodes.size() - kPer, version), common::InputError) << version;
  }
}

// Map format 11 had one group per filter pose and no re-rooting: its keyframe nodes read as
// such, and the map goes on as a new one would.
TEST(KeyframeNodes, AFormat11ReducedGraphIsReadWithAGroupPerPose) {
  esdf::Esdf written;
  chain(written);
  common::BinaryWriter w;
  written.writeState(w);
  w.boolean(true);
  w.size(kChain);
  for (size_t k = 0; k < kChain; ++k) {
    w.i32(static_cast<std::int32_t>(k));
    w.boolean(false);
  }
  w.size(0);
  w.size(kChain);
  for (size_t k = 0; k < kChain; ++k) w.u8(k == 7 ? 3 : 0);
  const std::string b = w.take();
  common::BinaryReader r(b.data(), b.size(), "test");
  esdf::Esdf filter, fresh;
  slam::KeyframeNodes back(filter, true), nodes(fresh, true);
  filter.readState(r);
  back.readState(r, kChain, 11);
  r.expectEnd();
  chain(fresh, nodes);
  const Vec3 z = esdf::between(nodes.mean(7), nodes.mean(kChain - 1));
  for (slam::KeyframeNodes* n : {&back, &nodes}) {
    EXPECT_TRUE(n->observeRelative(7, kChain - 1, z, stepOmega(), true).accepted);
    EXPECT_FALSE(n->add(kChain - 1, step(kChain), stepOmega()));
    EXPECT_EQ(n->node(kChain), 7);
  }
  EXPECT_EQ(back.mean(kChain), nodes.mean(kChain));
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
// Without reduction each keyframe is a filter pose of its own; with it the revisit adds poses
// only until its first closures re-root it (its arrival and the keyframes before the first
// confirmed closure), then hangs from the first pass's poses; it closes as often, and its
// keyframes stay where the first pass put the places.
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
  EXPECT_LE(reduced->map->filter()->size(), 200 + static_cast<int>(kPer));
  size_t hung = 0;
  for (size_t k = 200; k <= 260; ++k) hung += reduced->map->nodes()->hung(k) ? 1 : 0;
  EXPECT_GE(hung, 61 - kPer);
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
  const Mat3 omega = kCloseOmega;
  // A closure of the newest keyframe to keyframe 24 re-roots there (and leaves the factor
  // stale), and three keyframes more hang from 24's pose.
  EXPECT_TRUE(nodes.observeRelative(24, kChain - 1, esdf::between(nodes.mean(24), nodes.mean(kChain - 1)), omega, true).accepted);
  for (size_t k = kChain; k < kChain + 3; ++k) EXPECT_FALSE(nodes.add(k - 1, step(k), stepOmega()));
  // Filter poses 0 and 8; 4 and the hung kChain; kChain and kChain + 2, both hung from 24.
  const std::vector<std::pair<size_t, size_t>> pairs{{0, 8}, {4, kChain}, {kChain, kChain + 2}};
  ASSERT_FALSE(nodes.hung(0) || nodes.hung(8) || nodes.hung(4));
  ASSERT_TRUE(nodes.hung(kChain) && nodes.hung(kChain + 2) && nodes.node(kChain + 2) == 24);
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
