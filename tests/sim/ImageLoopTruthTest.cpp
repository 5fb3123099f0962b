// Image loop truth against views of a straight facade, where what each camera sees is known in
// closed form: a camera at (s, 0) looking at +y sees the wall y = W between x = s - W and s + W
// (90° field of view), and column c's ray meets it at x = s - W (cx - c - 0.5) / fx.
#include <gtest/gtest.h>

#include <cmath>

#include "urbanslam/common/Error.h"
#include "urbanslam/sim/ImageLoopTruth.h"
#include "urbanslam/sim/LoopTruth.h"

using namespace urbanslam;
using namespace urbanslam::sim;

namespace {

constexpr int kWidth = 640;
constexpr double kFx = kWidth / 2.0, kCx = kWidth / 2.0;  // 90° horizontal field of view

std::vector<double> bearings() {
  std::vector<double> b(kWidth);
  for (int x = 0; x < kWidth; ++x) b[static_cast<size_t>(x)] = std::atan2(kCx - (x + 0.5), kFx);
  return b;
}

// Column ranges of a camera at (s, 0) facing +y towards the wall y = wall_y.
std::vector<double> facadeRanges(double wall_y) {
  std::vector<double> r;
  for (double b : bearings()) r.push_back(wall_y / std::cos(b));
  return r;
}

std::vector<float> asFloat(const std::vector<double>& r) { return std::vector<float>(r.begin(), r.end()); }

// The fraction of the sampled columns of the camera at s_from whose wall point lies in [lo, hi].
double expectedFraction(double s_from, double wall_y, int stride, double lo, double hi) {
  int n = 0, in = 0;
  for (int c = 0; c < kWidth; c += stride, ++n) {
    const double x = s_from - wall_y * (kCx - c - 0.5) / kFx;
    in += (x >= lo && x <= hi);
  }
  return static_cast<double>(in) / n;
}

}  // namespace

TEST(ImageLoopTruth, OverlapOfTwoViewsOfAFacadeIsTheSharedStretch) {
  LoopTruthOptions o;
  ImageLoopTruth truth(o, bearings());
  const double wall = 40;  // columns 8 apart sample the wall 1 m apart here
  const auto ranges = asFloat(facadeRanges(wall));
  for (double s : {0.5, 7.0, 23.0, 55.0}) {
    const common::Pose2 from{s, 0, M_PI / 2}, to{0, 0, M_PI / 2};
    const double expected = expectedFraction(s, wall, o.image_column_stride, -wall, wall);
    EXPECT_NEAR(truth.overlap(from, ranges, to, ranges), expected, 1.5 * o.image_column_stride / double(kWidth)) << "shift " << s;
  }
}

TEST(ImageLoopTruth, FindsARevisitThatEndPointMatchingMisses) {
  // Half a metre beside an earlier view of a facade 40 m away: the same picture. End points of
  // every 8th column fall 1 m apart on the wall, so most have no earlier end point within
  // 0.3 m; the ray test does not depend on where the samples fall.
  LoopTruthOptions o;
  o.min_gap_s = 1;
  const auto ranges = facadeRanges(40);
  ImageLoopTruth truth(o, bearings());
  EXPECT_TRUE(truth.add(0, {0, 0, M_PI / 2}, ranges).empty());
  const auto pairs = truth.add(10, {0.5, 0, M_PI / 2}, ranges);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_GT(pairs[0].overlap, 0.95);
  EXPECT_NEAR(pairs[0].distance_m, 0.5, 1e-9);

  LoopTruthFinder points(o);
  auto endPoints = [&](double s) {
    std::vector<Vec2> p;
    const auto b = bearings();
    for (size_t c = 0; c < b.size(); c += static_cast<size_t>(o.image_column_stride))
      p.push_back({s - ranges[c] * std::sin(b[c]), ranges[c] * std::cos(b[c])});
    return p;
  };
  points.add(0, {0, 0}, endPoints(0));
  EXPECT_TRUE(points.add(10, {0.5, 0}, endPoints(0.5)).empty());
}

TEST(ImageLoopTruth, AHiddenStretchIsNotSeen) {
  // A pillar 5 m in front of the earlier camera hides the middle of its view (columns 240..399).
  LoopTruthOptions o;
  ImageLoopTruth truth(o, bearings());
  const double wall = 20;
  const auto open = facadeRanges(wall);
  auto blocked = open;
  for (int c = 240; c < 400; ++c) blocked[static_cast<size_t>(c)] = 5 / std::cos(bearings()[static_cast<size_t>(c)]);
  // Hidden wall stretch: between the rays of the pillar's edge columns.
  const double edge_left = wall * (kCx - 240) / kFx, edge_right = wall * (kCx - 400) / kFx;  // x = -W tan(b)
  const double hidden_lo = -edge_left, hidden_hi = -edge_right;
  const common::Pose2 from{0, 0, M_PI / 2}, to{0, 0, M_PI / 2};
  const double visible = expectedFraction(0, wall, o.image_column_stride, -wall, wall) -
                         expectedFraction(0, wall, o.image_column_stride, hidden_lo, hidden_hi);
  EXPECT_NEAR(truth.overlap(from, asFloat(open), to, asFloat(blocked)), visible, 2.0 * o.image_column_stride / double(kWidth));
  EXPECT_NEAR(truth.overlap(from, asFloat(open), to, asFloat(open)), 1.0, 1e-12);
}

TEST(ImageLoopTruth, AFacadeMuchFurtherAwayOrBehindTheCameraIsNotTheSameView) {
  LoopTruthOptions o;
  ImageLoopTruth truth(o, bearings());
  // The earlier camera 15 m back from a facade the new one sees from 5 m: three times as far.
  const auto near = asFloat(facadeRanges(5)), far = asFloat(facadeRanges(20));
  EXPECT_EQ(truth.overlap({0, 15, M_PI / 2}, near, {0, 0, M_PI / 2}, far), 0.0);
  // Facing away from the facade.
  EXPECT_EQ(truth.overlap({0, 0, M_PI / 2}, near, {0, 0, -M_PI / 2}, near), 0.0);
}

TEST(ImageLoopTruth, PairsNeedTimeGapDistanceAndHeading) {
  LoopTruthOptions o;  // 30 s, 15 m, 45°
  ImageLoopTruth truth(o, bearings());
  const auto r = facadeRanges(10);
  EXPECT_TRUE(truth.add(0, {0, 0, M_PI / 2}, r).empty());
  EXPECT_TRUE(truth.add(10, {0.2, 0, M_PI / 2}, r).empty());                    // too soon
  EXPECT_TRUE(truth.add(40, {0.2, 0, M_PI / 2 + 50 * M_PI / 180}, r).empty());  // turned away
  EXPECT_EQ(truth.add(80, {0.3, 0, M_PI / 2}, r).size(), 2u);                   // both earlier views
  EXPECT_TRUE(truth.add(120, {16.0, 0, M_PI / 2}, r).empty());                  // over 15 m from every earlier view
}

TEST(ImageLoopTruth, RejectsColumnsThatDoNotMatchTheCamera) {
  LoopTruthOptions o;
  EXPECT_THROW(ImageLoopTruth(o, {0.1}), common::InputError);
  EXPECT_THROW(ImageLoopTruth(o, {0.1, 0.2}), common::InputError);
  ImageLoopTruth truth(o, bearings());
  EXPECT_THROW(truth.add(0, {0, 0, 0}, {1.0, 2.0}), common::InputError);
}
