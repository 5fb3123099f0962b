// The simulated camera: projection against the pinhole model's analytic pixel positions, facade
// textures fixed to the facade (not to the image), repeated designs looking the same, images a
// feature matcher can work with, and reproducibility.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <tuple>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>

#include "urbanslam/sim/CameraRenderer.h"
#include "urbanslam/sim/CityModel.h"
#include "urbanslam/sim/Driver.h"
#include "urbanslam/sim/SurfaceTexture.h"
#include "StreetViews.h"

using namespace urbanslam;
using namespace urbanslam::sim;
using test::city1km;
using test::streetView;

namespace {

// A few known walls, ray cast by brute force: an independent reference for the projection.
class KnownWalls : public WallRayCaster {
 public:
  std::vector<Segment> segments;
  bool raycast(Vec2 o, Vec2 d, double max_range, RayHit& hit) const override {
    hit.range = kNoHit;
    for (const Segment& s : segments) {
      const double r = raySegment(o, d, s);
      if (r < hit.range && r <= max_range) {
        hit.range = r;
        hit.segment = s;
        hit.u_m = s.u0_m + norm(o + r * d - s.a);
      }
    }
    return hit.range < kNoHit;
  }
};

// Exact geometry: no noise, no fog.
CameraOptions clean() {
  CameraOptions c;
  c.enabled = true;
  c.noise_sigma = 0;
  c.fog_distance_m = 0;
  return c;
}

uint8_t at(const io::CameraImage& im, int x, int y) { return (*im.pixels)[static_cast<size_t>(y) * im.width + x]; }

cv::Mat toMat(const io::CameraImage& im) { return cv::Mat(im.height, im.width, CV_8U, const_cast<uint8_t*>(im.pixels->data())).clone(); }

// A look id whose featureless wall is darker than anything else in the image (sky > 160, ground
// at least 88 within 10 m), so wall pixels can be told apart by a threshold.
SurfaceLook darkWall(double height) {
  for (uint32_t id = 1;; ++id) {
    const SurfaceTexture t({id, SurfaceKind::Featureless, static_cast<float>(height)});
    if (t.sample(0.5, 2.0) < 74) return {id, SurfaceKind::Featureless, static_cast<float>(height)};
  }
}

}  // namespace

TEST(CameraRenderer, AWallAtDistanceDHasTheAnalyticPixelHeightAndEdges) {
  for (double d : {10.0, 14.0, 22.5}) {                   // from 10 m, the wall's top is inside the image
    const double wall_h = 9.0, left = 4.0, right = -3.0;  // wall from y = -3 (right) to y = 4 (left)
    KnownWalls w;
    w.segments.push_back({{d, right}, {d, left}, darkWall(wall_h), 0.f});
    CameraOptions c = clean();
    c.height_m = 1.6;
    const CameraRenderer cam(c, w, 1);
    const io::CameraImage im = cam.render(0, 0, {0, 0, 0});
    ASSERT_EQ(im.width, 640);
    const double f = cam.fx();
    EXPECT_NEAR(f, 320.0, 1e-9);  // 90 degrees over 640 px
    // Column: fy * wall_height / d wall pixels, from the top at cy - fy (H - h) / d.
    for (double lateral : {0.8 * left, 0.0, 0.8 * right}) {  // columns on the wall
      const int x = static_cast<int>(cam.cx() - f * lateral / d);
      int rows = 0, first = -1;
      for (int y = 0; y < im.height; ++y)
        if (at(im, x, y) < 82) {
          ++rows;
          if (first < 0) first = y;
        }
      const double z = d;  // depth along the optical axis is d in every column of a fronto-parallel wall
      EXPECT_NEAR(rows, f * wall_h / z, 1.0) << "d " << d << " column " << x;
      EXPECT_NEAR(first, cam.cy() - f * (wall_h - c.height_m) / z, 1.0) << "d " << d << " column " << x;
    }
    // Edges: the wall's ends at lateral offsets left / right project to cx - f y / d.
    const int row = static_cast<int>(cam.cy()) - 5;  // just above the horizon: wall or sky
    int x0 = -1, x1 = -1;
    for (int x = 0; x < im.width; ++x)
      if (at(im, x, row) < 82) {
        if (x0 < 0) x0 = x;
        x1 = x;
      }
    const double left_edge = cam.cx() - f * left / d, right_edge = cam.cx() - f * right / d;
    EXPECT_NEAR(x0, left_edge, 1.0) << d;
    EXPECT_NEAR(x1 + 1, right_edge, 1.0) << d;
  }
}

TEST(CameraRenderer, AFacadePointHasTheSameTextureFromTwoViewpoints) {
  KnownWalls w;
  const SurfaceLook look{0x5eed1u, SurfaceKind::Facade, static_cast<float>(facadeHeight(0x5eed1u, SurfaceKind::Facade))};
  w.segments.push_back({{12, 30}, {12, -30}, look, 3.f});  // facing the cameras at x < 12
  const CameraRenderer cam(clean(), w, 1);
  const common::Pose2 a{0, 0, 0}, b{3.0, -2.5, 0.35};  // 3.9 m apart, turned by 20 degrees
  const io::CameraImage ia = cam.render(0, 0, a), ib = cam.render(1, 0, b);
  const double ch = clean().height_m;
  // Facade points (y, h) projected analytically into both images.
  auto project = [&](const common::Pose2& p, double y, double h, int& col, int& row) {
    const common::Pose2 local = common::between(p, {12, y, 0});
    if (local.x <= 0.5) return false;
    col = static_cast<int>(std::floor(cam.cx() - cam.fx() * local.y / local.x));
    row = static_cast<int>(std::floor(cam.cy() - cam.fy() * (h - ch) / local.x));
    return col >= 0 && col < ia.width && row >= 0 && row < ia.height;
  };
  int compared = 0, same = 0, varied = 0;
  uint8_t first = 0;
  for (double y = -6; y <= 6; y += 0.37)
    for (double h = 0.3; h < look.height_m; h += 0.29) {
      int ca, ra, cb, rb;
      if (!project(a, y, h, ca, ra) || !project(b, y, h, cb, rb)) continue;
      const int va = at(ia, ca, ra), vb = at(ib, cb, rb);
      ++compared;
      same += std::abs(va - vb) <= 2;
      if (compared == 1) first = static_cast<uint8_t>(va);
      varied += std::abs(va - first) > 20;
    }
  ASSERT_GT(compared, 300);
  EXPECT_GT(varied, compared / 5);  // the facade is textured, so agreement means something
  // Nearest-texel sampling at the edges of texture details may pick the neighbour.
  EXPECT_GT(same, compared * 85 / 100) << same << " of " << compared;
  std::printf("[ info ] %d of %d facade points agree within 2 grey levels\n", same, compared);
}

TEST(CameraRenderer, RepeatedDesignsLookTheSameAndOtherDesignsDiffer) {
  const CityModel city(city1km());
  // The longest segment of each facade look, by (look, length, texture start): a design's copies
  // share all three. Segments along +x only, so the sun shades all compared copies alike.
  std::map<std::tuple<uint32_t, long, long>, std::vector<Segment>> copies;
  for (int tx = 0; tx < 5; ++tx)
    for (int ty = 0; ty < 5; ++ty)
      for (const Segment& s : city.tile(tx, ty)->segments) {
        if (s.look.kind != SurfaceKind::Facade || s.b.x - s.a.x < 6 || std::fabs(s.b.y - s.a.y) > 1e-9) continue;
        // Only facades with open ground in front (a street, not an alley between two buildings),
        // where the views below stand.
        const Vec2 mid = 0.5 * (s.a + s.b);
        if (city.raycast({mid.x, mid.y - 0.01}, {0, -1}, 8.0) != kNoHit) continue;
        copies[{s.look.id, std::lround(norm(s.b - s.a) * 1000), std::lround(s.u0_m * 1000)}].push_back(s);
      }
  // Render each copy from 7 m in front of its middle (outward normal: the right of its direction).
  CameraOptions c = clean();
  c.cy_px = 400;  // more of the facade above the horizon
  const CameraRenderer cam(c, city, 1);
  auto view = [&](const Segment& s) {
    const Vec2 mid = 0.5 * (s.a + s.b);
    return cam.render(0, 0, {mid.x, mid.y - 7.0, M_PI / 2});
  };
  // Compared: the middle columns, rows showing the facade between 6.5 m (above cars, trees and
  // lamp posts) and its top.
  auto difference = [&](const io::CameraImage& p, const io::CameraImage& q, double top) {
    const int r0 = static_cast<int>(std::ceil(cam.cy() - cam.fy() * (top - c.height_m) / 7.0)) + 1;
    const int r1 = static_cast<int>(std::floor(cam.cy() - cam.fy() * (6.5 - c.height_m) / 7.0));
    double sum = 0;
    int n = 0;
    for (int y = std::max(0, r0); y <= r1; ++y)
      for (int x = 260; x < 380; ++x, ++n) sum += std::abs(int(at(p, x, y)) - int(at(q, x, y)));
    return n > 0 ? sum / n : -1.0;
  };
  int pairs = 0;
  std::vector<std::pair<Segment, io::CameraImage>> designs;
  for (const auto& [key, list] : copies) {
    if (list.size() < 2) continue;
    const Segment& s0 = list[0];
    // Copies in different places (not the same wall split by a tile border).
    for (size_t k = 1; k < list.size() && pairs < 6; ++k) {
      if (norm(list[k].a - s0.a) < 50) continue;
      const double d = difference(view(s0), view(list[k]), s0.look.height_m);
      ASSERT_GE(d, 0);
      std::printf("[ info ] design %08x: copies at (%.1f, %.1f) and (%.1f, %.1f), mean |difference| %.2f\n", std::get<0>(key), s0.a.x,
                  s0.a.y, list[k].a.x, list[k].a.y, d);
      EXPECT_LT(d, 1.0) << "design " << std::get<0>(key) << " at " << s0.a.x << "," << s0.a.y << " and " << list[k].a.x << ","
                        << list[k].a.y;
      ++pairs;
      if (designs.empty() || designs.back().first.look.id != s0.look.id) designs.emplace_back(s0, view(s0));
      break;
    }
  }
  ASSERT_GE(pairs, 2) << "the city should repeat designs";
  ASSERT_GE(designs.size(), 2u);
  for (size_t i = 1; i < designs.size(); ++i) {
    const double top = std::min(designs[0].first.look.height_m, designs[i].first.look.height_m);
    const double d = difference(designs[0].second, designs[i].second, top);
    std::printf("[ info ] designs %08x and %08x: mean |difference| %.1f\n", designs[0].first.look.id, designs[i].first.look.id, d);
    EXPECT_GT(d, 10.0);
  }
}

TEST(CameraRenderer, SiftFindsAndMatchesFeaturesOnStreetViews) {
  const CityModel city(city1km());
  CameraOptions c;
  c.enabled = true;
  c.cy_px = 360;
  const CameraRenderer cam(c, city, 1);
  auto sift = cv::SIFT::create();
  int views = 0;
  for (double t : {8.0, 40.0, 75.0}) {
    const io::CameraImage i0 = cam.render(0, 0, streetView(city.streets(), t));
    const io::CameraImage i1 = cam.render(1, 0, streetView(city.streets(), t, 1.0));  // 1 m further on
    std::vector<cv::KeyPoint> k0, k1;
    cv::Mat d0, d1;
    sift->detectAndCompute(toMat(i0), cv::noArray(), k0, d0);
    sift->detectAndCompute(toMat(i1), cv::noArray(), k1, d1);
    EXPECT_GE(k0.size(), 200u) << "t " << t;
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_L2).knnMatch(d0, d1, knn, 2);
    std::vector<cv::Point2f> p0, p1;
    for (const auto& m : knn)
      if (m.size() == 2 && m[0].distance < 0.8f * m[1].distance) {
        p0.push_back(k0[m[0].queryIdx].pt);
        p1.push_back(k1[m[0].trainIdx].pt);
      }
    ASSERT_GE(p0.size(), 8u) << "t " << t;
    std::vector<uchar> inlier;
    cv::findFundamentalMat(p0, p1, cv::FM_RANSAC, 3.0, 0.99, inlier);
    const int inliers = cv::countNonZero(inlier);
    EXPECT_GE(inliers, 50) << "t " << t << ": " << k0.size() << " keypoints, " << p0.size() << " ratio-test matches";
    ++views;
    std::printf("[ info ] t %.0f s: %zu / %zu SIFT keypoints, %zu ratio-test matches, %d F-RANSAC inliers\n", t, k0.size(), k1.size(),
                p0.size(), inliers);
  }
  EXPECT_EQ(views, 3);
}

TEST(CameraRenderer, TheSameSeedGivesIdenticalImagesAndTheNoiseSeedOnlyTheNoise) {
  const CityModel a(city1km()), b(city1km());
  CameraOptions c;
  c.enabled = true;
  const common::Pose2 pose = streetView(a.streets(), 20.0);
  const io::CameraImage ia = CameraRenderer(c, a, 1).render(5, 0, pose);
  const io::CameraImage ib = CameraRenderer(c, b, 1).render(5, 0, pose);
  EXPECT_TRUE(*ia.pixels == *ib.pixels);
  // Another image index or noise stream: other noise on the same picture.
  c.noise_seed = 3;
  const io::CameraImage ic = CameraRenderer(c, b, 1).render(5, 0, pose);
  EXPECT_FALSE(*ia.pixels == *ic.pixels);
  double diff = 0;
  for (size_t i = 0; i < ia.pixels->size(); ++i) diff += std::abs(int((*ia.pixels)[i]) - int((*ic.pixels)[i]));
  diff /= static_cast<double>(ia.pixels->size());
  EXPECT_LT(diff, 4.0);  // noise_sigma 2: a mean absolute difference of ~2.3
  EXPECT_GT(diff, 0.5);
}
