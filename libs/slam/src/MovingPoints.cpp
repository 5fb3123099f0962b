#include "urbanslam/slam/MovingPoints.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/common/ParallelJobs.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/slam/FreeSpaceCache.h"
#include "urbanslam/slam/KeyframeGrid.h"

namespace urbanslam::slam {

namespace {

// Keyframes a thread takes at a time, and the threads (each holding its cache of free space).
constexpr size_t kRunKeyframes = 256;
constexpr size_t kMaxWorkers = 2;

}  // namespace

MovingPointsResult findMovingPoints(const std::vector<io::PosedScan>& scans, const MovingPointsOptions& o) {
  common::Stopwatch sw;
  MovingPointsResult out;
  const size_t views = static_cast<size_t>(std::max(0, o.views));
  // The map's own spatial index, over the scans' positions.
  KeyframeGrid grid(std::max(o.reach_m, 1.0));
  for (size_t i = 0; i < scans.size(); ++i) grid.insert(i, scans[i].pose.x, scans[i].pose.y);
  // Runs of consecutive keyframes (which mostly share their judges) shared out to two threads,
  // each with its own cache of free space; every point's verdict is the same whichever thread
  // gives it, and the runs' verdicts are joined in order.
  struct Worker {
    explicit Worker(FreeSpaceCache c) : cache(std::move(c)) {}
    FreeSpaceCache cache;
    io::LaserScan buffer;
    std::vector<Eigen::Vector2d> world;
    std::vector<size_t> near, judges;
    std::vector<int> votes;
    std::vector<char> state;
  };
  const size_t runs = (scans.size() + kRunKeyframes - 1) / kRunKeyframes;
  const size_t n_workers = common::workerCount(runs, kMaxWorkers);
  std::vector<Worker> workers;
  workers.reserve(n_workers);
  while (workers.size() < n_workers) workers.emplace_back(FreeSpaceCache(o.margin_m, o.margin_fraction, std::max<size_t>(64, 8 * views)));
  std::vector<io::PointMask> kept(runs);  // per run, a bit per point (10^6 keyframes hold 10^8 points)
  common::runJobs(runs, workers.size(), [&](size_t w, size_t run) {
    Worker& k = workers[w];
    for (size_t i = run * kRunKeyframes; i < std::min(scans.size(), (run + 1) * kRunKeyframes); ++i) {
      const common::Pose2& pose = scans[i].pose;
      const double c = std::cos(pose.phi), s = std::sin(pose.phi);
      k.world.clear();
      // The points in the order the cloud writers visit them (forEachMapPoint).
      for (const auto& p : io::scanToPoints(scans[i].get(k.buffer), true))
        k.world.emplace_back(pose.x + c * p.x - s * p.y, pose.y + s * p.x + c * p.y);
      k.near.clear();
      grid.query(pose.x, pose.y, o.reach_m, k.near);
      // Within reach, in log order, the keyframe itself left out.
      k.near.erase(std::remove_if(
                       k.near.begin(), k.near.end(),
                       [&](size_t j) { return j == i || !(std::hypot(scans[j].pose.x - pose.x, scans[j].pose.y - pose.y) <= o.reach_m); }),
                   k.near.end());
      std::sort(k.near.begin(), k.near.end());
      // Spread over time: the judges evenly among the keyframes within reach, in log order.
      k.judges.clear();
      if (k.near.size() <= views) {
        k.judges = k.near;
      } else {
        for (size_t m = 0; m < views; ++m) k.judges.push_back(k.near[(2 * m + 1) * k.near.size() / (2 * views)]);
      }
      k.votes.assign(k.world.size(), 0);
      for (size_t j : k.judges) {
        k.state.assign(k.world.size(), alignment::BeamFreeSpace::kUnseen);
        k.cache.get(j, [&](io::LaserScan& buffer) -> const io::LaserScan& { return scans[j].get(buffer); })
            .classify(k.world, scans[j].pose, k.state);
        for (size_t p = 0; p < k.world.size(); ++p) k.votes[p] += k.state[p] == alignment::BeamFreeSpace::kSeenThrough ? 1 : 0;
      }
      for (int v : k.votes) kept[run].push(v < o.min_views);
    }
  });
  for (const io::PointMask& run : kept)
    for (size_t p = 0; p < run.size(); ++p) {
      const bool stays = run.keeps(p);
      out.static_points.push(stays);
      out.moving += stays ? 0 : 1;
    }
  out.seconds = sw.seconds();
  return out;
}

}  // namespace urbanslam::slam
