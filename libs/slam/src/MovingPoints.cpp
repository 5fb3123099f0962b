#include "urbanslam/slam/MovingPoints.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <list>
#include <unordered_map>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/slam/KeyframeGrid.h"

namespace urbanslam::slam {

namespace {

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
  // The map's own spatial index, over the scans' positions.
  KeyframeGrid grid(std::max(o.reach_m, 1.0));
  for (size_t i = 0; i < scans.size(); ++i) grid.insert(i, scans[i].pose.x, scans[i].pose.y);
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
    near.clear();
    grid.query(pose.x, pose.y, o.reach_m, near);
    // Within reach, in log order, the keyframe itself left out.
    near.erase(
        std::remove_if(near.begin(), near.end(),
                       [&](size_t k) { return k == i || !(std::hypot(scans[k].pose.x - pose.x, scans[k].pose.y - pose.y) <= o.reach_m); }),
        near.end());
    std::sort(near.begin(), near.end());
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
