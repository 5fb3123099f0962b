#include "urbanslam/sim/LoopTruth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace urbanslam::sim {

LoopTruthFinder::LoopTruthFinder(const LoopTruthOptions& options) : options_(options) {}

std::vector<Vec2> LoopTruthFinder::endPoints(const io::LaserScan& scan, const common::Pose2& vehicle, int stride) {
  const common::Pose2 sensor = common::compose(vehicle, scan.sensor_pose);
  std::vector<Vec2> out;
  for (size_t i = 0; i < scan.size(); i += static_cast<size_t>(stride)) {
    if (!scan.valid[i]) continue;
    const double a = sensor.phi + scan.bearing(i), r = scan.ranges[i];
    out.push_back({sensor.x + r * std::cos(a), sensor.y + r * std::sin(a)});
  }
  return out;
}

int64_t positionCellKey(double x, double y, double cell_m) {
  const auto cx = static_cast<int64_t>(std::floor(x / cell_m));
  const auto cy = static_cast<int64_t>(std::floor(y / cell_m));
  // Shifted unsigned: a left shift of a negative value is undefined behaviour.
  return static_cast<int64_t>(static_cast<uint64_t>(cx) << 32) ^ (cy & 0xffffffff);
}

std::vector<LoopPair> LoopTruthFinder::add(const io::LaserScan& scan, const common::Pose2& vehicle) {
  const common::Pose2 sp = common::compose(vehicle, scan.sensor_pose);
  return add(scan.timestamp, {sp.x, sp.y}, endPoints(scan, vehicle, options_.point_stride));
}

std::vector<LoopPair> LoopTruthFinder::add(double t, Vec2 sensor, const std::vector<Vec2>& points) {
  Entry e{t, sensor, {}};
  for (const Vec2& p : points) {
    e.xy.push_back(static_cast<float>(p.x));
    e.xy.push_back(static_cast<float>(p.y));
  }
  std::vector<LoopPair> out;
  const size_t n_new = e.xy.size() / 2;
  const double r2 = options_.match_radius_m * options_.match_radius_m;
  // The window along x, a little wider than the radius: the test below is on float differences.
  const double r = options_.match_radius_m + 1e-3;
  const double d = options_.max_distance_m;
  if (n_new > 0) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        auto it = cells_.find(positionCellKey(e.sensor.x + dx * d, e.sensor.y + dy * d, d));
        if (it == cells_.end()) continue;
        for (uint32_t k : it->second) {
          const Entry& o = scans_[k];
          const double dist = norm(o.sensor - e.sensor);
          if (e.t - o.t < options_.min_gap_s || dist > d || o.xy.empty()) continue;
          // The older scan's points are sorted by x (below): only those within the radius along x
          // are looked at, found by bisection, and none beyond its extent along y. A pair that can
          // no longer reach min_overlap is given up (it would not be reported).
          const size_t n_old = o.xy.size() / 2;
          size_t hit = 0;
          bool reachable = true;
          for (size_t i = 0; i < n_new && reachable; ++i) {
            reachable = static_cast<double>(hit + n_new - i) / static_cast<double>(n_new) >= options_.min_overlap;
            const float px = e.xy[2 * i], py = e.xy[2 * i + 1];
            if (!reachable || py < o.min_y_max_y[0] - r || py > o.min_y_max_y[1] + r) continue;
            size_t lo = 0, hi = n_old;
            while (lo < hi) {
              const size_t mid = (lo + hi) / 2;
              if (static_cast<double>(o.xy[2 * mid]) < px - r)
                lo = mid + 1;
              else
                hi = mid;
            }
            for (size_t j = lo; j < n_old && static_cast<double>(o.xy[2 * j]) <= px + r; ++j) {
              const double ex = px - o.xy[2 * j], ey = py - o.xy[2 * j + 1];
              if (ex * ex + ey * ey <= r2) {
                ++hit;
                break;
              }
            }
          }
          const double overlap = static_cast<double>(hit) / static_cast<double>(n_new);
          if (reachable && overlap >= options_.min_overlap) out.push_back({o.t, e.t, overlap, dist});
        }
      }
  }
  std::sort(out.begin(), out.end(), [](const LoopPair& a, const LoopPair& b) { return a.t_old < b.t_old; });
  // Kept sorted by x for the later scans' bisection (the overlap asks only whether a point is near).
  std::vector<std::pair<float, float>> sorted(n_new);
  for (size_t i = 0; i < n_new; ++i) sorted[i] = {e.xy[2 * i], e.xy[2 * i + 1]};
  std::sort(sorted.begin(), sorted.end());
  e.min_y_max_y = {std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest()};
  for (size_t i = 0; i < n_new; ++i) {
    e.xy[2 * i] = sorted[i].first, e.xy[2 * i + 1] = sorted[i].second;
    e.min_y_max_y[0] = std::min(e.min_y_max_y[0], sorted[i].second);
    e.min_y_max_y[1] = std::max(e.min_y_max_y[1], sorted[i].second);
  }
  cells_[positionCellKey(e.sensor.x, e.sensor.y, options_.max_distance_m)].push_back(static_cast<uint32_t>(scans_.size()));
  scans_.push_back(std::move(e));
  return out;
}

}  // namespace urbanslam::sim
