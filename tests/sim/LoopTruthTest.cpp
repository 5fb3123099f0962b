// Ground-truth loop pairs against a brute-force search over all pairs of scans.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "urbanslam/sim/LoopTruth.h"
#include "urbanslam/sim/SimulatedSource.h"

using namespace urbanslam;
using namespace urbanslam::sim;

TEST(LoopTruth, SpatialHashFindsExactlyTheBruteForcePairs) {
  // A tiny city (one block with streets round it): the drive laps it and revisits constantly.
  SimOptions o;
  o.city.seed = 5;
  o.city.area_km2 = 0.05;
  o.route.route_length_km = 1.0;
  o.laser.rate_hz = 2;
  o.odometry.enabled = false;
  SimulatedSource sim(o);
  LoopTruthFinder finder(o.loops);
  struct Scan {
    double t;
    Vec2 sensor;
    std::vector<Vec2> pts;
  };
  std::vector<Scan> scans;
  std::map<std::pair<double, double>, double> found;
  io::Measurement m;
  common::Pose2 truth;
  while (sim.next(m)) {
    if (const auto* r = std::get_if<io::ReferencePose>(&m)) truth = r->pose;
    if (const auto* s = std::get_if<io::LaserScan>(&m)) {
      for (const LoopPair& p : finder.add(*s, truth)) found[{p.t_old, p.t_new}] = p.overlap;
      // Independent end points: the scan's own beam geometry, placed by hand.
      Scan sc;
      sc.t = s->timestamp;
      const double c = std::cos(truth.phi), sn = std::sin(truth.phi);
      sc.sensor = {truth.x + c * s->sensor_pose.x - sn * s->sensor_pose.y, truth.y + sn * s->sensor_pose.x + c * s->sensor_pose.y};
      const double heading = truth.phi + s->sensor_pose.phi;
      for (size_t i = 0; i < s->size(); i += static_cast<size_t>(o.loops.point_stride))
        if (s->valid[i])
          sc.pts.push_back({sc.sensor.x + s->ranges[i] * std::cos(heading + s->bearing(i)),
                            sc.sensor.y + s->ranges[i] * std::sin(heading + s->bearing(i))});
      scans.push_back(std::move(sc));
    }
  }
  ASSERT_GT(scans.size(), 150u);

  std::map<std::pair<double, double>, double> brute;
  for (size_t b = 0; b < scans.size(); ++b)
    for (size_t a = 0; a < b; ++a) {
      const Scan &older = scans[a], &newer = scans[b];
      if (newer.t - older.t < o.loops.min_gap_s || norm(newer.sensor - older.sensor) > o.loops.max_distance_m) continue;
      if (newer.pts.empty() || older.pts.empty()) continue;
      size_t hit = 0;
      for (const Vec2& p : newer.pts) {
        double best = 1e300;
        for (const Vec2& q : older.pts) best = std::min(best, norm(p - q));
        hit += best <= o.loops.match_radius_m;
      }
      const double overlap = static_cast<double>(hit) / static_cast<double>(newer.pts.size());
      if (overlap >= o.loops.min_overlap) brute[{older.t, newer.t}] = overlap;
    }
  ASSERT_GT(brute.size(), 20u) << "the drive should revisit its streets";
  // The finder stores end points as floats: pairs right at the threshold may differ, nothing else.
  for (const auto& [key, overlap] : found) {
    auto it = brute.find(key);
    ASSERT_TRUE(it != brute.end() || overlap < o.loops.min_overlap + 0.02) << key.first << " " << key.second;
    if (it != brute.end()) {
      EXPECT_NEAR(it->second, overlap, 0.02);
    }
  }
  for (const auto& [key, overlap] : brute)
    if (overlap >= o.loops.min_overlap + 0.02) {
      EXPECT_TRUE(found.count(key)) << key.first << " " << key.second;
    }
  EXPECT_GT(found.size(), brute.size() * 9 / 10);
}
