// Keyframes hung from the filter poses of others (a reduced pose graph), against a reference
// filter in which each hung keyframe is a pose of its own: a leaf added by ESDF augmentation from
// the pose it hangs from, by the same measurements. A leaf informs nothing else, so its mean and
// covariances are what the hung keyframe's must be; an observation between two leaves is what
// the reduced filter's composed observation between their poses stands for.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <memory>
#include <tuple>
#include <vector>

#include "ConstantScan.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/GlobalSlam.h"
#include "urbanslam/slam/KeyframeNodes.h"
#include "urbanslam/slam/Map.h"

using namespace urbanslam;
using esdf::Mat3;
using esdf::Vec3;

namespace {

constexpr size_t kChain = 30;  // keyframes 0..kChain-1 with poses of their own

// The odometry of the chain: a curving drive, each step a metre.
Vec3 step(size_t k) { return {1.0, 0.05 * std::sin(0.3 * static_cast<double>(k)), 0.04 * std::cos(0.2 * static_cast<double>(k))}; }
Mat3 stepOmega() { return Vec3(1 / 0.01, 1 / 0.02, 1 / 1e-4).asDiagonal(); }

// Keyframes 0..kChain-1 in `filter` through `nodes`, each from the one before.
void chain(esdf::Esdf& filter, slam::KeyframeNodes& nodes) {
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-9);
  nodes.addFirst();
  for (size_t k = 1; k < kChain; ++k) ASSERT_TRUE(nodes.add(k - 1, step(k), stepOmega()));
}

// The same chain as poses 0..kChain-1 of a plain filter.
void chain(esdf::Esdf& filter) {
  filter.initialise(Vec3::Zero(), Mat3::Identity() * 1e-9);
  for (size_t k = 1; k < kChain; ++k) filter.augmentRelative(static_cast<int>(k - 1), step(k), stepOmega());
}

// The last chain keyframe closes with keyframe 8; the next two keyframes follow by z1, z2 and
// hang from the last chain keyframe's pose. The reference has them as leaves: L2 = x_29 ⊕ z1,
// L3 = L2 ⊕ z2.
const Vec3 kClosure{0.3, -0.2, 0.1};
const Mat3 kClosureCov = Vec3(0.02, 0.03, 0.001).asDiagonal();
const Vec3 kZ1{1.0, 0.1, 0.05}, kZ2{0.9, -0.05, -0.02};

struct Pair {
  esdf::Esdf reduced_filter, reference;
  slam::KeyframeNodes nodes{reduced_filter, true};
  int l2 = 0, l3 = 0;  // the reference's leaves for keyframes kChain and kChain + 1
};

std::unique_ptr<Pair> hungPair() {
  auto p = std::make_unique<Pair>();
  chain(p->reduced_filter, p->nodes);
  p->nodes.closed(8, kChain - 1, kClosure, kClosureCov);
  EXPECT_FALSE(p->nodes.add(kChain - 1, kZ1, stepOmega()));
  EXPECT_FALSE(p->nodes.add(kChain, kZ2, stepOmega()));
  chain(p->reference);
  p->l2 = p->reference.augmentRelative(kChain - 1, kZ1, stepOmega());
  p->l3 = p->reference.augmentRelative(p->l2, kZ2, stepOmega());
  return p;
}

void expectNear(const Mat3& a, const Mat3& b, double tol) { EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tol) << "\n" << a << "\n\n" << b; }

}  // namespace

TEST(KeyframeNodes, AHungKeyframeIsTheLeafPoseItStandsFor) {
  auto p = hungPair();
  slam::KeyframeNodes& n = p->nodes;
  ASSERT_EQ(n.size(), kChain + 2);
  EXPECT_EQ(n.nodes(), static_cast<int>(kChain));  // no pose added
  EXPECT_TRUE(n.hung(kChain));
  EXPECT_EQ(n.node(kChain + 1), static_cast<int>(kChain - 1));
  EXPECT_EQ(n.tailSize(), 2u);
  for (auto [k, leaf] : {std::pair<size_t, int>{kChain, p->l2}, {kChain + 1, p->l3}}) {
    EXPECT_LE((n.mean(k) - p->reference.mean(leaf)).norm(), 1e-12);
    expectNear(n.marginalCovariance(k, esdf::CovarianceMode::Exact), p->reference.marginalCovariance(leaf, esdf::CovarianceMode::Exact),
               1e-9);
    // Relative to a keyframe of the chain, in both orders.
    expectNear(n.relativeCovariance(3, k, esdf::CovarianceMode::Exact),
               p->reference.relativeCovariance(3, leaf, esdf::CovarianceMode::Exact), 1e-9);
    expectNear(n.relativeCovariance(k, 20, esdf::CovarianceMode::Exact),
               p->reference.relativeCovariance(leaf, 20, esdf::CovarianceMode::Exact), 1e-9);
  }
  // Two keyframes of one pose: their offsets are taken as independent, which can only widen the
  // relative covariance (here the leaves are a chain, the second uncertain by z2 alone).
  const Mat3 widened = n.relativeCovariance(kChain, kChain + 1, esdf::CovarianceMode::Exact) -
                       p->reference.relativeCovariance(p->l2, p->l3, esdf::CovarianceMode::Exact);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat3>(widened).eigenvalues().minCoeff(), -1e-12);
}

// An observation of keyframe 12 from the second hung keyframe (2 cm and 0.5° off what the
// estimate predicts) goes into the reduced filter between their poses, its measurement composed
// with the offset. After a full recovery the chain's poses are where the reference puts them
// with the observation between its leaf and pose 12, to second order in the innovation: the
// hung keyframe keeps its offset, where the reference's leaf takes a share of the correction.
TEST(KeyframeNodes, AnObservationOfAHungKeyframeIsTheObservationOfItsLeaf) {
  for (const bool backwards : {false, true}) {
    auto p = hungPair();
    std::vector<Vec3> before;
    for (size_t k = 0; k < kChain; ++k) before.push_back(p->reference.mean(static_cast<int>(k)));
    const Vec3 predicted = esdf::between(p->reference.mean(p->l3), p->reference.mean(12));
    Vec3 z = predicted + Vec3(0.02, -0.02, 0.5 * M_PI / 180);
    const Mat3 omega = Vec3(1 / 0.0004, 1 / 0.0004, 1 / 3e-5).asDiagonal();
    if (backwards) {
      z = esdf::inverse(z);
      EXPECT_TRUE(p->nodes.observeRelative(12, kChain + 1, z, omega, true).accepted);
      EXPECT_TRUE(p->reference.observeRelative(12, p->l3, z, omega, true).accepted);
    } else {
      EXPECT_TRUE(p->nodes.observeRelative(kChain + 1, 12, z, omega, true).accepted);
      EXPECT_TRUE(p->reference.observeRelative(p->l3, 12, z, omega, true).accepted);
    }
    EXPECT_EQ(p->reduced_filter.size(), static_cast<int>(kChain));
    p->reduced_filter.recover();
    p->reference.recover();
    double worst = 0, moved = 0;
    for (size_t k = 0; k < kChain; ++k) {
      worst = std::max(worst, (p->reduced_filter.mean(static_cast<int>(k)) - p->reference.mean(static_cast<int>(k))).head<2>().norm());
      moved = std::max(moved, (p->reference.mean(static_cast<int>(k)) - before[k]).head<2>().norm());
    }
    EXPECT_GE(moved, 5e-3) << backwards;
    EXPECT_LE(worst, 2e-2 * moved) << backwards;
  }
}

// A closure of a tail keyframe hangs it from the earlier keyframe's pose, where the closure and
// local SLAM's chain put it, each weighed by its covariance: at the closure's measurement when
// that is far the more certain, where the chain put it when the closure is far vaguer, between
// them otherwise, and known better than by the chain alone. The tail keyframe after it follows.
TEST(KeyframeNodes, AClosedTailKeyframeHangsWhereTheClosureAndTheChainPutIt) {
  struct Result {
    double to_measured, to_chain;
    Mat3 cov, chained_cov;
  };
  const auto closedWith = [](const Mat3& cov) {
    auto p = hungPair();
    const Vec3 chained = p->nodes.mean(kChain);
    Result r;
    r.chained_cov = p->nodes.marginalCovariance(kChain, esdf::CovarianceMode::Exact);
    // The measurement puts keyframe kChain 5 cm and 0.6° from where the chain has it.
    const Vec3 c = esdf::between(p->reduced_filter.mean(20), chained) + Vec3(0.05, -0.03, 0.01);
    p->nodes.closed(20, kChain, c, cov);
    EXPECT_EQ(p->nodes.node(kChain), 20);
    EXPECT_EQ(p->nodes.node(kChain + 1), 20);
    EXPECT_EQ(p->nodes.tailSize(), 1u);
    EXPECT_LE((p->nodes.mean(kChain + 1) - esdf::compose(p->nodes.mean(kChain), kZ2)).norm(), 1e-12);
    const Vec3 measured = esdf::compose(p->reduced_filter.mean(20), c);
    r.to_measured = (p->nodes.mean(kChain) - measured).head<2>().norm();
    r.to_chain = (p->nodes.mean(kChain) - chained).head<2>().norm();
    r.cov = p->nodes.marginalCovariance(kChain, esdf::CovarianceMode::Exact);
    return r;
  };
  const double apart = std::hypot(0.05, 0.03);
  EXPECT_LE(closedWith(Mat3::Identity() * 1e-10).to_measured, 1e-3 * apart);
  EXPECT_LE(closedWith(Mat3::Identity() * 1e4).to_chain, 1e-3 * apart);
  const Result r = closedWith(Vec3(0.1, 0.2, 1e-3).asDiagonal());  // about what the chain knows
  EXPECT_GT(r.to_measured, 0.05 * apart);
  EXPECT_GT(r.to_chain, 0.05 * apart);
  EXPECT_LT(r.to_measured + r.to_chain, 1.5 * apart);
  EXPECT_LT(r.cov(0, 0) + r.cov(1, 1), r.chained_cov(0, 0) + r.chained_cov(1, 1));
}

// A tail that never closes gets poses of its own, each linked to its predecessor as it came:
// the filter of the keyframes then holds what a filter without reduction holds for them.
TEST(KeyframeNodes, APromotedTailIsAChainOfOwnPoses) {
  auto p = hungPair();
  p->nodes.promoteTail();
  EXPECT_EQ(p->nodes.tailSize(), 0u);
  EXPECT_EQ(p->nodes.nodes(), static_cast<int>(kChain + 2));
  EXPECT_FALSE(p->nodes.hung(kChain));
  EXPECT_EQ(p->nodes.node(kChain + 1), static_cast<int>(kChain + 1));
  esdf::Esdf plain;
  chain(plain);
  plain.augmentRelative(kChain - 1, kZ1, stepOmega());
  plain.augmentRelative(kChain, kZ2, stepOmega());
  p->reduced_filter.recover();
  plain.recover();
  for (size_t k = 0; k < kChain + 2; ++k) EXPECT_LE((p->nodes.mean(k) - plain.mean(static_cast<int>(k))).norm(), 1e-9) << k;
  expectNear(p->nodes.marginalCovariance(kChain + 1, esdf::CovarianceMode::Exact),
             plain.marginalCovariance(kChain + 1, esdf::CovarianceMode::Exact), 1e-9);
}

TEST(KeyframeNodes, ReadBackHangsTheSame) {
  auto p = hungPair();
  common::BinaryWriter w;
  p->reduced_filter.writeState(w);
  p->nodes.writeState(w);
  const std::string bytes = w.take();
  common::BinaryReader r(bytes.data(), bytes.size(), "test");
  esdf::Esdf filter;
  slam::KeyframeNodes nodes(filter, true);
  filter.readState(r);
  nodes.readState(r, kChain + 2);
  r.expectEnd();
  for (size_t k = 0; k < kChain + 2; ++k) {
    EXPECT_EQ(nodes.node(k), p->nodes.node(k));
    EXPECT_EQ(nodes.mean(k), p->nodes.mean(k));
  }
  EXPECT_EQ(nodes.tailSize(), p->nodes.tailSize());
  // The next keyframe hangs as it would have.
  EXPECT_FALSE(nodes.add(kChain + 1, kZ1, stepOmega()));
  EXPECT_FALSE(p->nodes.add(kChain + 1, kZ1, stepOmega()));
  EXPECT_EQ(nodes.mean(kChain + 2), p->nodes.mean(kChain + 2));
  // A map without reduction is refused by a reader with it, and the other way round.
  common::BinaryReader again(bytes.data(), bytes.size(), "test");
  esdf::Esdf other;
  slam::KeyframeNodes plain(other, false);
  other.readState(again);
  EXPECT_THROW(plain.readState(again, kChain + 2), common::InputError);
}

// Global SLAM over a revisit: keyframes 0-199 a metre apart along x, then from keyframe 200 the
// same places from x = 100 on again, every scan the same (the alignments measure the true
// relative pose, identity). Without reduction each keyframe of the revisit is a filter pose of
// its own; with it the revisit closes, hangs from the first pass's poses and adds (next to)
// none, and its keyframes stay where the first pass put the places.
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
      o->global->addKeyframe({k, static_cast<double>(k), {}, true, false, {}}, io::CompactScan(test::constantScan(k, 10.0, 80)), c);
      o->global->closeLoops(k, std::chrono::steady_clock::now());
    }
    o->global->finish();
    return o;
  };
  const auto plain = run(false), reduced = run(true);
  ASSERT_GE(plain->stats.closures_accepted, 40u);
  EXPECT_EQ(plain->map->filter()->size(), 261);
  EXPECT_GE(reduced->stats.closures_accepted, 40u);
  EXPECT_LE(reduced->map->filter()->size(), 205);
  size_t hung = 0;
  for (size_t k = 200; k <= 260; ++k) hung += reduced->map->nodes()->hung(k) ? 1 : 0;
  EXPECT_GE(hung, 55u);
  for (size_t k = 200; k <= 260; ++k) {
    const common::Pose2 a = reduced->map->keyframes()[k].pose, b = plain->map->keyframes()[k].pose;
    EXPECT_NEAR(a.x, b.x, 0.05) << k;
    EXPECT_NEAR(a.y, b.y, 0.05) << k;
    EXPECT_NEAR(a.x, static_cast<double>(k) - 100, 0.1) << k;
  }
}
