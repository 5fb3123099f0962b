#include "urbanslam/sim/LoopTruth.h"

#include <algorithm>
#include <cmath>

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
          size_t hit = 0;
          for (size_t i = 0; i < n_new; ++i) {
            const float px = e.xy[2 * i], py = e.xy[2 * i + 1];
            for (size_t j = 0; j < o.xy.size(); j += 2) {
              const double ex = px - o.xy[j], ey = py - o.xy[j + 1];
              if (ex * ex + ey * ey <= r2) {
                ++hit;
                break;
              }
            }
          }
          const double overlap = static_cast<double>(hit) / static_cast<double>(n_new);
          if (overlap >= options_.min_overlap) out.push_back({o.t, e.t, overlap, dist});
        }
      }
  }
  std::sort(out.begin(), out.end(), [](const LoopPair& a, const LoopPair& b) { return a.t_old < b.t_old; });
  cells_[positionCellKey(e.sensor.x, e.sensor.y, options_.max_distance_m)].push_back(static_cast<uint32_t>(scans_.size()));
  scans_.push_back(std::move(e));
  return out;
}

}  // namespace urbanslam::sim
