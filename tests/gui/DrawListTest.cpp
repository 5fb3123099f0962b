#include <gtest/gtest.h>

#include <cmath>

#include "model/DrawList.h"

using namespace urbanslam;
using namespace urbanslam::gui;

namespace {

MapSnapshot threeKeyframes() {
  MapSnapshot s;
  auto pts = std::make_shared<const std::vector<io::Point2>>(std::vector<io::Point2>{{1, 0}, {0, 1}});
  s.keyframes.push_back({0, 0.0, {0, 0, 0}, pts, nullptr});
  s.keyframes.push_back({1, 1.0, {2, 0, M_PI / 2}, pts, nullptr});
  s.keyframes.push_back({2, 2.0, {2, 3, M_PI}, pts, nullptr});
  return s;
}

}  // namespace

TEST(DrawList, PointsAreScanPointsPlacedAtKeyframePoses) {
  const DrawList d = buildDrawList(threeKeyframes(), {});
  EXPECT_EQ(d.keyframes_drawn, 3u);
  ASSERT_EQ(d.map_points.size(), 6u);
  // Keyframe 1 at (2, 0) facing +y: vehicle-frame (1, 0) lands at (2, 1), (0, 1) at (1, 0).
  EXPECT_NEAR(d.map_points[2].x, 2, 1e-6);
  EXPECT_NEAR(d.map_points[2].y, 1, 1e-6);
  EXPECT_NEAR(d.map_points[3].x, 1, 1e-6);
  EXPECT_NEAR(d.map_points[3].y, 0, 1e-6);
  ASSERT_EQ(d.trajectory.size(), 2u);
  EXPECT_FLOAT_EQ(d.trajectory[1].y1, 3);
  // The current scan is the last keyframe's, highlighted.
  ASSERT_EQ(d.current_scan.size(), 2u);
  EXPECT_EQ(d.current_scan[0].colour, palette::kCurrentScan);
  EXPECT_NEAR(d.current_scan[0].x, 1, 1e-6);  // (2,3) facing -x: (1,0) -> (1,3)
  EXPECT_FLOAT_EQ(d.bounds.xmin, 0);
  EXPECT_FLOAT_EQ(d.bounds.ymax, 3);
}

TEST(DrawList, AgeColoursRunFromOldToNewAndLayersHideThings) {
  const MapSnapshot s = threeKeyframes();
  const DrawList d = buildDrawList(s, {});
  EXPECT_EQ(d.map_points[0].colour, ageColour(0, 3));
  EXPECT_EQ(d.map_points[5].colour, ageColour(2, 3));
  EXPECT_FALSE(ageColour(0, 3) == ageColour(2, 3));
  EXPECT_GT(ageColour(0, 3).b, ageColour(0, 3).r);  // old = blue
  EXPECT_GT(ageColour(2, 3).r, ageColour(2, 3).b);  // new = warm
  Layers off;
  off.map_points = off.trajectory = off.current_scan = false;
  const DrawList e = buildDrawList(s, off);
  EXPECT_TRUE(e.map_points.empty());
  EXPECT_TRUE(e.trajectory.empty());
  EXPECT_TRUE(e.current_scan.empty());
  EXPECT_EQ(e.keyframes_drawn, 3u);
  Layers height;
  height.colouring = PointColouring::Height;
  EXPECT_EQ(buildDrawList(s, height).map_points[0].colour, palette::kHeight);
}

TEST(DrawList, ClosuresSplitByOutcomeAndCandidates) {
  MapSnapshot s = threeKeyframes();
  s.closures.push_back({0, 2, 2.0, slam::Proposer::Laser, 0.9, true, ""});
  s.closures.push_back({1, 2, 2.0, slam::Proposer::Laser, 0.2, false, "gating"});
  s.closures.push_back({0, 7, 2.0, slam::Proposer::Laser, 0.2, false, "alignment"});  // unknown keyframe: skipped
  s.candidates = {0, 1};
  const DrawList d = buildDrawList(s, {});
  ASSERT_EQ(d.closures_accepted.size(), 1u);
  ASSERT_EQ(d.closures_rejected.size(), 1u);
  EXPECT_FLOAT_EQ(d.closures_accepted[0].x1, 2);
  EXPECT_FLOAT_EQ(d.closures_accepted[0].y1, 3);
  EXPECT_FLOAT_EQ(d.closures_rejected[0].x0, 2);
  EXPECT_EQ(d.candidates.size(), 2u);
  Layers no_rejected;
  no_rejected.closures_rejected = false;
  EXPECT_TRUE(buildDrawList(s, no_rejected).closures_rejected.empty());
}

// The ellipse's axes are 3 sigma along the eigenvectors of the (x, y) covariance block.
TEST(DrawList, UncertaintyEllipseFromCovariance) {
  const double a = 0.3;  // rotate diag(4, 1) by 0.3 rad
  const double c = std::cos(a), s = std::sin(a);
  const double sxx = 4 * c * c + 1 * s * s, syy = 4 * s * s + 1 * c * c, sxy = (4 - 1) * c * s;
  const auto e = uncertaintyEllipse({1, 2, 0}, {sxx, sxy, 0, sxy, syy, 0, 0, 0, 0.1});
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->a, 3 * 2.0, 1e-5);
  EXPECT_NEAR(e->b, 3 * 1.0, 1e-5);
  EXPECT_NEAR(e->angle_rad, a, 1e-6);
  EXPECT_FLOAT_EQ(e->cx, 1);
  EXPECT_FALSE(uncertaintyEllipse({0, 0, 0}, {}));
}

TEST(DrawList, SelectedKeyframeScanIsHighlighted) {
  Layers l;
  l.selected_keyframe = 1;
  const DrawList d = buildDrawList(threeKeyframes(), l);
  ASSERT_EQ(d.selected_scan.size(), 2u);
  EXPECT_EQ(d.selected_scan[0].colour, palette::kSelected);
  EXPECT_NEAR(d.selected_scan[0].x, 2, 1e-6);  // keyframe 1's (1, 0) lands at (2, 1)
  EXPECT_NEAR(d.selected_scan[0].y, 1, 1e-6);
  EXPECT_TRUE(buildDrawList(threeKeyframes(), {}).selected_scan.empty());
}

TEST(DrawList, PickingFindsTheNearestKeyframeWithinTolerance) {
  const MapSnapshot s = threeKeyframes();
  EXPECT_EQ(pickKeyframe(s, 2.2, 2.7, 1.0), std::optional<size_t>(2));
  EXPECT_EQ(pickKeyframe(s, 1.9, 0.1, 1.0), std::optional<size_t>(1));
  EXPECT_FALSE(pickKeyframe(s, 10, 10, 1.0));
}
