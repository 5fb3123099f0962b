// Each feature of §3.2.1 against values worked out by hand on crafted scans, and the invariances
// the thesis requires: rotating the sensor, reversing the beam order, and (for features that are
// functions of the point set) any order of the beams.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "urbanslam/laser_loop/ScanFeatures.h"

using namespace urbanslam;
using namespace urbanslam::laser_loop;

namespace {

constexpr double kDeg = M_PI / 180.0;

io::LaserScan makeScan(const std::vector<double>& ranges, double angle_min, double increment, double max_range = 80) {
  io::LaserScan s;
  for (double r : ranges) {
    const bool ok = r > 0 && r < max_range;
    s.ranges.push_back(static_cast<float>(ok ? r : max_range));
    s.valid.push_back(ok ? 1 : 0);
  }
  s.angle_min_rad = angle_min;
  s.angle_increment_rad = increment;
  s.max_range_m = max_range;
  return s;
}

double get(const FeatureVector& f, Feature k) { return f[static_cast<int>(k)]; }

// A 360° scan of an irregular room with a doorway to the far outside, 1° beams: realistic
// enough that every feature is non-trivial.
io::LaserScan roomScan360() {
  std::vector<double> r;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-0.02, 0.02);
  for (int i = 0; i < 360; ++i) {
    const double a = i * kDeg;
    // Rectangle 8 × 5 m seen from (1, −0.5) off centre, plus a pillar and an open door.
    const double hx = 4.0 - 1.0 * (std::cos(a) > 0 ? 1 : -1), hy = 2.5 + 0.5 * (std::sin(a) > 0 ? -1 : 1);
    const double tx = std::fabs(std::cos(a)) > 1e-9 ? hx / std::fabs(std::cos(a)) : 1e9;
    const double ty = std::fabs(std::sin(a)) > 1e-9 ? hy / std::fabs(std::sin(a)) : 1e9;
    double d = std::min(tx, ty);
    if (i >= 40 && i < 48) d = 1.2 + 0.01 * (i - 40);  // pillar
    if (i >= 100 && i < 112) d = 0;                    // door: no return
    if (i >= 200 && i < 204) d = 45.0;                 // window: beyond r_max
    r.push_back(d > 0 ? d + noise(rng) : 0);
  }
  return makeScan(r, -M_PI, kDeg);
}

FeatureParams params(double r_max, double gate, int min_size) {
  FeatureParams p;
  p.r_max_m = r_max;
  p.g_max_dist_m = gate;
  p.g_min_size = min_size;
  return p;
}

void expectSame(const FeatureVector& a, const FeatureVector& b, const std::string& what) {
  for (int i = 0; i < kFeatureCount; ++i) EXPECT_NEAR(a[i], b[i], 1e-9 * std::max(1.0, std::fabs(a[i]))) << what << ": " << featureName(i);
}

}  // namespace

TEST(ScanFeatures, NamesRoundTrip) {
  for (int i = 0; i < kFeatureCount; ++i) EXPECT_EQ(featureIndex(featureName(i)), i);
  EXPECT_EQ(featureIndex("nope"), -1);
}

// Open 180° scan, 45° beams at 0..180°: ranges 2, 2, (no return), 1, 1; r_max 10, gate 1.0 m,
// groups of more than 1 point. Clamped points p0=(2,0), p1=(√2,√2), p2=(0,10), p3=(−√2/2,√2/2),
// p4=(−1,0). Values worked out by hand (the irrational ones evaluated with a calculator).
TEST(ScanFeatures, HandComputedOpenScan) {
  const auto f = computeFeatures(makeScan({2, 2, 0, 1, 1}, 0, 45 * kDeg), params(10, 1.0, 1));
  const double s45 = std::sqrt(0.5);
  // 3.6: ½ sin45° (2·2 + 2·10 + 10·1 + 1·1) = 17.5 sin45°
  EXPECT_NEAR(get(f, Feature::Area), 17.5 * s45, 1e-12);
  // 3.7: (2+2+10+1+1)/5
  EXPECT_NEAR(get(f, Feature::AverageRange), 3.2, 1e-12);
  // 3.8–3.9: short points summed, divided by N = 5: (1+√2/2, 3√2/2)/5 → 0.5445810706358822
  EXPECT_NEAR(get(f, Feature::MeanCentroid), std::hypot((1 + s45) / 5, 3 * s45 / 5), 1e-12);
  EXPECT_NEAR(get(f, Feature::MeanCentroid), 0.5445810706358822, 1e-12);
  // twentieth: all five clamped points: (1+√2/2, 3√2/2 + 10)/5 → 2.4481880682134367
  EXPECT_NEAR(get(f, Feature::ClampedCentroid), 2.4481880682134367, 1e-12);
  // 3.10: ½ sin45° (4+4+1+1)
  EXPECT_NEAR(get(f, Feature::CloseArea), 5 * s45, 1e-12);
  // chords: |p0p1| = 4 sin22.5°, |p3p4| = 2 sin22.5°; only |p3p4| < 1.0 m
  const double s22 = std::sin(22.5 * kDeg);
  EXPECT_NEAR(get(f, Feature::Distance), 6 * s22, 1e-12);
  EXPECT_NEAR(get(f, Feature::CloseDistance), 2 * s22, 1e-12);
  // 3.16 with p2 at r_max: + |p1p2| = √(2 + (10−√2)²) + |p2p3| = √(1/2 + (10−√2/2)²)
  EXPECT_NEAR(get(f, Feature::FarDistance),
              6 * s22 + std::sqrt(2 + std::pow(10 - std::sqrt(2.0), 2)) + std::sqrt(0.5 + std::pow(10 - s45, 2)), 1e-12);
  // Groups: clusters {p0}, {p1}, {p3,p4}; only the last has more than 1 point.
  EXPECT_EQ(get(f, Feature::GroupCount), 1);
  EXPECT_EQ(get(f, Feature::GroupMeanSize), 2);
  EXPECT_EQ(get(f, Feature::MaxRangeCount), 1);
  EXPECT_EQ(get(f, Feature::Size), 4);
  // No three consecutive short beams: no curvature, no angular difference.
  EXPECT_EQ(get(f, Feature::CurvatureMean), 0);
  EXPECT_EQ(get(f, Feature::CurvatureStd), 0);
  EXPECT_EQ(get(f, Feature::MeanAngularDifference), 0);
  // 3.20: Σ |p_i − mean| / 5 over the short points, mean from 3.8.
  EXPECT_NEAR(get(f, Feature::MeanDeviation), 1.1329318449764414, 1e-12);
  // 3.21: sample std of {4 sin22.5°, 2 sin22.5°} = 2 sin22.5° / √2
  EXPECT_NEAR(get(f, Feature::Regularity), 2 * s22 / std::sqrt(2.0), 1e-12);
  // 3.24: sample std of {2,2,1,1} = √(1/3)
  EXPECT_NEAR(get(f, Feature::StdRange), std::sqrt(1.0 / 3), 1e-12);
  // 3.13 solved by Cramer's rule on the 3×3 normal equations (independent of the centred solver).
  EXPECT_NEAR(get(f, Feature::CircularityResidual), 0.17239449244120053, 1e-10);
  EXPECT_NEAR(get(f, Feature::CircularityRadius), 1.4834685043265632, 1e-10);
}

// log_features: each value of the hand-checked open scan above becomes sign(f)·ln(1 + |f|); the
// reference applies that transform here to the plain features (3.7's 3.2 m → ln 4.2).
TEST(ScanFeatures, LogFeaturesAreTheLogOfThePlainFeatures) {
  auto p = params(10, 1.0, 1);
  const auto scan = makeScan({2, 2, 0, 1, 1}, 0, 45 * kDeg);
  const auto plain = computeFeatures(scan, p);
  p.log_features = true;
  const auto logf = computeFeatures(scan, p);
  EXPECT_NEAR(get(logf, Feature::AverageRange), std::log(4.2), 1e-12);
  EXPECT_EQ(get(logf, Feature::CurvatureMean), 0);  // ln(1 + 0)
  for (int k = 0; k < kFeatureCount; ++k) {
    const double v = plain[static_cast<size_t>(k)];
    EXPECT_NEAR(logf[static_cast<size_t>(k)], (v < 0 ? -1 : 1) * std::log(1 + std::fabs(v)), 1e-12) << featureName(k);
  }
}

// Closed 360° scan of four unit-range beams: the square (1,0),(0,1),(−1,0),(0,−1).
TEST(ScanFeatures, HandComputedClosedSquare) {
  const auto f = computeFeatures(makeScan({1, 1, 1, 1}, 0, 90 * kDeg), params(10, 2.0, 2));
  EXPECT_NEAR(get(f, Feature::Area), 2.0, 1e-12);       // four triangles of ½
  EXPECT_NEAR(get(f, Feature::CloseArea), 2.0, 1e-12);  // ½ · 4 · sin 90°
  EXPECT_NEAR(get(f, Feature::AverageRange), 1.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::MeanCentroid), 0.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::ClampedCentroid), 0.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::Distance), 4 * std::sqrt(2.0), 1e-12);  // wrap-around side included
  EXPECT_NEAR(get(f, Feature::CloseDistance), 4 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(get(f, Feature::FarDistance), 4 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(get(f, Feature::CircularityResidual), 0.0, 1e-12);  // on the unit circle
  EXPECT_NEAR(get(f, Feature::CircularityRadius), 1.0, 1e-12);
  // Triangle (1,0),(0,1),(−1,0): area 1, sides √2, √2, 2 → k = 4/(√2·√2·2) = 1 at every corner.
  EXPECT_NEAR(get(f, Feature::CurvatureMean), 1.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::CurvatureStd), 0.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::MeanAngularDifference), 2 * M_PI, 1e-12);  // four 90° turns
  EXPECT_EQ(get(f, Feature::GroupCount), 1);                             // one ring of 4 > 2
  EXPECT_EQ(get(f, Feature::GroupMeanSize), 4);
  EXPECT_NEAR(get(f, Feature::MeanDeviation), 1.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::Regularity), 0.0, 1e-12);
  EXPECT_NEAR(get(f, Feature::StdRange), 0.0, 1e-12);
  EXPECT_EQ(get(f, Feature::Size), 4);
  EXPECT_EQ(get(f, Feature::MaxRangeCount), 0);
}

// Open three-beam arc (1,0),(0,1),(−1,0): one triple, a 90° turn, curvature 1; with g_min_size 2
// the three points are one group.
TEST(ScanFeatures, HandComputedArc) {
  const auto f = computeFeatures(makeScan({1, 1, 1}, 0, 90 * kDeg), params(10, 2.0, 2));
  EXPECT_NEAR(get(f, Feature::MeanAngularDifference), M_PI / 2, 1e-12);
  EXPECT_NEAR(get(f, Feature::CurvatureMean), 1.0, 1e-12);
  EXPECT_EQ(get(f, Feature::GroupCount), 1);
  EXPECT_EQ(get(f, Feature::GroupMeanSize), 3);
  EXPECT_NEAR(get(f, Feature::Area), 1.0, 1e-12);  // two triangles of ½ (no wrap on an open scan)
  // Gate 1.0 < √2 breaks every link: three singletons, no group.
  const auto g = computeFeatures(makeScan({1, 1, 1}, 0, 90 * kDeg), params(10, 1.0, 0));
  EXPECT_EQ(get(g, Feature::GroupCount), 3);  // g_min_size 0: singletons count
  EXPECT_EQ(get(g, Feature::CloseDistance), 0);
}

TEST(ScanFeatures, InvariantUnderSensorRotation360) {
  const auto p = params(30, 1.0, 3);
  const io::LaserScan base = roomScan360();
  const auto f0 = computeFeatures(base, p);
  EXPECT_GT(get(f0, Feature::GroupCount), 1);
  EXPECT_GT(get(f0, Feature::MaxRangeCount), 0);
  for (int shift : {1, 17, 90, 181, 359}) {
    // Rotating the sensor by k beams moves every range k places along the ring.
    io::LaserScan rot = base;
    std::rotate(rot.ranges.begin(), rot.ranges.begin() + shift, rot.ranges.end());
    std::rotate(rot.valid.begin(), rot.valid.begin() + shift, rot.valid.end());
    expectSame(f0, computeFeatures(rot, p), "cyclic shift " + std::to_string(shift));
    // The same through the general polar path with arbitrary bearings (a non-beam angle too).
    PolarScan polar = toPolar(rot);
    for (auto& b : polar.bearings) b += 0.123;
    expectSame(f0, computeFeatures(polar, p), "polar shift " + std::to_string(shift));
  }
  io::LaserScan moved = base;
  moved.angle_min_rad += 1.234;  // any heading
  expectSame(f0, computeFeatures(moved, p), "angle_min");
}

TEST(ScanFeatures, LogFeaturesInvariantUnderSensorRotation360) {
  auto p = params(30, 1.0, 3);
  p.log_features = true;
  const io::LaserScan base = roomScan360();
  const auto f0 = computeFeatures(base, p);
  for (int shift : {1, 90, 181}) {
    io::LaserScan rot = base;
    std::rotate(rot.ranges.begin(), rot.ranges.begin() + shift, rot.ranges.end());
    std::rotate(rot.valid.begin(), rot.valid.begin() + shift, rot.valid.end());
    expectSame(f0, computeFeatures(rot, p), "cyclic shift " + std::to_string(shift));
  }
}

TEST(ScanFeatures, InvariantUnderHeadingFor180DegreeScans) {
  const auto p = params(30, 1.0, 3);
  io::LaserScan s = roomScan360();
  s.ranges.resize(181);
  s.valid.resize(181);
  const auto f0 = computeFeatures(s, p);
  for (double a : {-3.0, -0.5, 0.7, 2.9}) {
    io::LaserScan t = s;
    t.angle_min_rad = a;
    expectSame(f0, computeFeatures(t, p), "heading");
  }
}

TEST(ScanFeatures, InvariantUnderReversedBeamOrder) {
  const auto p = params(30, 1.0, 3);
  for (size_t n : {size_t(181), size_t(360)}) {
    io::LaserScan s = roomScan360();
    s.ranges.resize(n);
    s.valid.resize(n);
    io::LaserScan r = s;
    std::reverse(r.ranges.begin(), r.ranges.end());
    std::reverse(r.valid.begin(), r.valid.end());  // the mirror image of the scene
    expectSame(computeFeatures(s, p), computeFeatures(r, p), "reversed n=" + std::to_string(n));
  }
}

// Features defined on the point set (not on neighbours) do not care in which order the beams come.
TEST(ScanFeatures, SetFeaturesInvariantUnderBeamPermutation) {
  const auto p = params(30, 1.0, 3);
  PolarScan polar = toPolar(roomScan360());
  polar.closed = false;
  const auto f0 = computeFeatures(polar, p);
  std::vector<size_t> idx(polar.ranges.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::shuffle(idx.begin(), idx.end(), std::mt19937(3));
  PolarScan shuffled = polar;
  for (size_t i = 0; i < idx.size(); ++i) {
    shuffled.ranges[i] = polar.ranges[idx[i]];
    shuffled.bearings[i] = polar.bearings[idx[i]];
    shuffled.valid[i] = polar.valid[idx[i]];
  }
  const auto f1 = computeFeatures(shuffled, p);
  for (Feature k :
       {Feature::AverageRange, Feature::MeanCentroid, Feature::ClampedCentroid, Feature::CloseArea, Feature::CircularityResidual,
        Feature::CircularityRadius, Feature::MaxRangeCount, Feature::MeanDeviation, Feature::Size, Feature::StdRange})
    EXPECT_NEAR(get(f0, k), get(f1, k), 1e-9 * std::max(1.0, std::fabs(get(f0, k)))) << featureName(k);
}

TEST(ScanFeatures, MergedFrontAndBackLasers) {
  // Two 180° lasers back to back at the vehicle origin form one closed 360° scan equal to it.
  const io::LaserScan full = roomScan360();
  io::LaserScan front = full, back = full;
  front.ranges.assign(full.ranges.begin(), full.ranges.begin() + 180);
  front.valid.assign(full.valid.begin(), full.valid.begin() + 180);
  back.ranges.assign(full.ranges.begin() + 180, full.ranges.end());
  back.valid.assign(full.valid.begin() + 180, full.valid.end());
  back.angle_min_rad = full.angle_min_rad;
  back.sensor_pose.phi = M_PI;
  const PolarScan merged = mergeScans({front, back});
  EXPECT_TRUE(merged.closed);
  ASSERT_EQ(merged.ranges.size(), 360u);
  expectSame(computeFeatures(full, params(30, 1.0, 3)), computeFeatures(merged, params(30, 1.0, 3)), "merged");
}

TEST(ScanFeatures, EmptyAndAllFarScansAreFinite) {
  const auto p = params(10, 1.0, 3);
  for (const auto& f : {computeFeatures(makeScan({}, 0, kDeg), p), computeFeatures(makeScan({0, 0, 0, 50}, 0, kDeg), p)})
    for (double v : f) EXPECT_TRUE(std::isfinite(v));
}

// A 0.5° scan is compared at 1°: its features are those of every other beam.
TEST(ScanFeatures, FinerScansAreDecimatedToTheCommonResolution) {
  io::LaserScan fine = makeScan({}, -M_PI / 2, 0.5 * kDeg);
  io::LaserScan coarse = makeScan({}, -M_PI / 2, kDeg);
  const io::LaserScan room = roomScan360();
  for (int i = 0; i < 361; ++i) {
    fine.ranges.push_back(room.ranges[static_cast<size_t>(i / 2)] + 0.01f * static_cast<float>(i % 2));
    fine.valid.push_back(room.valid[static_cast<size_t>(i / 2)]);
    if (i % 2 == 0) {
      coarse.ranges.push_back(fine.ranges.back());
      coarse.valid.push_back(fine.valid.back());
    }
  }
  auto p = params(30, 1.0, 3);
  expectSame(computeFeatures(coarse, p), computeFeatures(fine, p), "decimated");
  p.beam_increment_deg = 0;  // every beam: the odd beams change the features
  EXPECT_NE(get(computeFeatures(fine, p), Feature::Size), get(computeFeatures(coarse, p), Feature::Size));
}
