#include "urbanslam/slam/MovingPoints.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <list>
#include <unordered_map>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/common/Timing.h"

namespace urbanslam::slam {

namespace {

// The keyframes' positions in square cells of the reach: a keyframe's judges are in the 3 x 3
// cells around it.
class PositionGrid {
 public:
  PositionGrid(const std::vector<io::PosedScan>& scans, double cell_m) : cell_(cell_m) {
    for (size_t i = 0; i < scans.size(); ++i) cells_[key(cellOf(scans[i].pose.x), cellOf(scans[i].pose.y))].push_back(i);
  }
  // Indices within reach of (x, y), ascending.
  void near(const std::vector<io::PosedScan>& scans, double x, double y, double reach_m, std::vector<size_t>& out) const {
    out.clear();
    const long long cx = cellOf(x), cy = cellOf(y);
    for (long long i = cx - 1; i <= cx + 1; ++i)
      for (long long j = cy - 1; j <= cy + 1; ++j)
        if (const auto it = cells_.find(key(i, j)); it != cells_.end())
          for (size_t k : it->second)
            if (std::hypot(scans[k].pose.x - x, scans[k].pose.y - y) <= reach_m) out.push_back(k);
    std::sort(out.begin(), out.end());
  }

 private:
  long long cellOf(double v) const { return static_cast<long long>(std::floor(v / cell_)); }
  // Shifted unsigned: a left shift of a negative value is undefined behaviour.
  static long long key(long long i, long long j) {
    return static_cast<long long>(static_cast<unsigned long long>(i) << 32) ^ (j & 0xffffffffLL);
  }
  double cell_;
  std::unordered_map<long long, std::vector<size_t>> cells_;
};

// The free space of the scans judged with recently, least recently used dropped: consecutive
// keyframes mostly share their judges.
class FreeSpaceCache {
 public:
  FreeSpaceCache(const std::vector<io::PosedScan>& scans, const MovingPointsOptions& o, size_t capacity)
      : scans_(scans), options_(o), capacity_(capacity) {
    model_.max_range_m = std::numeric_limits<double>::infinity();  // every return the scan kept
    model_.min_range_m = 0;
  }
  const alignment::BeamFreeSpace& get(size_t i) {
    if (const auto it = index_.find(i); it != index_.end()) {
      order_.splice(order_.begin(), order_, it->second);
      return it->second->second;
    }
    if (order_.size() >= capacity_) {
      index_.erase(order_.back().first);
      order_.pop_back();
    }
    const alignment::PointSet points = alignment::pointSetFromScan(scans_[i].get(buffer_), model_, true);
    order_.emplace_front(i, alignment::BeamFreeSpace(points, options_.margin_m, options_.margin_fraction));
    index_[i] = order_.begin();
    return order_.front().second;
  }

 private:
  const std::vector<io::PosedScan>& scans_;
  MovingPointsOptions options_;
  size_t capacity_;
  alignment::ScanModelOptions model_;
  io::LaserScan buffer_;
  std::list<std::pair<size_t, alignment::BeamFreeSpace>> order_;
  std::unordered_map<size_t, std::list<std::pair<size_t, alignment::BeamFreeSpace>>::iterator> index_;
};

}  // namespace

MovingPointsResult findMovingPoints(const std::vector<io::PosedScan>& scans, const MovingPointsOptions& o) {
  common::Stopwatch sw;
  MovingPointsResult out;
  const size_t views = static_cast<size_t>(std::max(0, o.views));
  const PositionGrid grid(scans, std::max(o.reach_m, 1.0));
  FreeSpaceCache cache(scans, o, std::max<size_t>(64, 8 * views));
  io::LaserScan buffer;
  std::vector<Eigen::Vector2d> world;
  std::vector<size_t> near, judges;
  std::vector<int> votes;
  std::vector<char> state;
  for (size_t i = 0; i < scans.size(); ++i) {
    const common::Pose2& pose = scans[i].pose;
    const double c = std::cos(pose.phi), s = std::sin(pose.phi);
    world.clear();
    // The points in the order the cloud writers visit them (forEachMapPoint).
    for (const auto& p : io::scanToPoints(scans[i].get(buffer), true))
      world.emplace_back(pose.x + c * p.x - s * p.y, pose.y + s * p.x + c * p.y);
    grid.near(scans, pose.x, pose.y, o.reach_m, near);
    near.erase(std::remove(near.begin(), near.end(), i), near.end());
    // Spread over time: the judges evenly among the keyframes within reach, in log order.
    judges.clear();
    if (near.size() <= views) {
      judges = near;
    } else {
      for (size_t m = 0; m < views; ++m) judges.push_back(near[(2 * m + 1) * near.size() / (2 * views)]);
    }
    votes.assign(world.size(), 0);
    for (size_t j : judges) {
      state.assign(world.size(), alignment::BeamFreeSpace::kUnseen);
      cache.get(j).classify(world, scans[j].pose, state);
      for (size_t k = 0; k < world.size(); ++k) votes[k] += state[k] == alignment::BeamFreeSpace::kSeenThrough ? 1 : 0;
    }
    for (int v : votes) {
      const bool moved = v >= o.min_views;
      out.static_points.push(!moved);
      out.moving += moved ? 1 : 0;
    }
  }
  out.seconds = sw.seconds();
  return out;
}

}  // namespace urbanslam::slam
