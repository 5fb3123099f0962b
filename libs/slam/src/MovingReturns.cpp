#include "urbanslam/slam/MovingReturns.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/slam/FreeSpaceCache.h"
#include "urbanslam/slam/Map.h"

namespace urbanslam::slam {

size_t hideMovingReturns(io::LaserScan& scan, const std::vector<ScanJudge>& judges, const MovingReturnsOptions& o) {
  if (judges.size() < static_cast<size_t>(std::max(1, o.min_views))) return 0;
  // The returns in the vehicle frame, each with its beam.
  std::vector<Eigen::Vector2d> points;
  for (const io::Point2& q : io::scanToPoints(scan, true)) points.emplace_back(q.x, q.y);
  std::vector<size_t> beams;
  for (size_t b = 0; b < scan.size(); ++b)
    if (scan.valid[b]) beams.push_back(b);
  std::vector<int> votes(points.size(), 0);
  std::vector<char> state;
  for (const ScanJudge& j : judges) {
    state.assign(points.size(), alignment::BeamFreeSpace::kUnseen);
    j.free->classify(points, j.pose, state);
    for (size_t p = 0; p < points.size(); ++p) votes[p] += state[p] == alignment::BeamFreeSpace::kSeenThrough ? 1 : 0;
  }
  // Only what spans min_width_m is hidden: a run of returns that the judges saw through, beam
  // after beam (a single beam between them not, as a judge's return may fall short of the margin
  // by chance), its ends that far apart. Narrower things fall between the judges' beams, which
  // pass them on either side (a post, a tree trunk tens of metres away: the trees of Victoria
  // Park), and what moved and can pull an alignment its own way is a vehicle.
  std::vector<size_t> hide, run;
  const auto close = [&] {
    if (!run.empty() && (points[run.back()] - points[run.front()]).norm() >= o.min_width_m)
      for (size_t q : run) hide.push_back(beams[q]);
    run.clear();
  };
  for (size_t p = 0; p < points.size(); ++p) {
    if (votes[p] < o.min_views) continue;
    if (!run.empty() && beams[p] > beams[run.back()] + 2) close();
    run.push_back(p);
  }
  close();
  for (size_t b : hide) scan.valid[b] = 0;
  return hide.size();
}

bool seesThroughEarlier(const Map& map, size_t k, size_t before, const std::function<common::Pose2(size_t)>& pose,
                        const MovingReturnsOptions& options) {
  if (before == 0 || !map.keyframes()[k].hasScan()) return false;
  const io::LaserScan current = map.scan(k);
  if (current.size() == 0) return false;
  MovingReturnsOptions one = options;
  one.min_views = 1;  // the one judge: the current scan
  const alignment::BeamFreeSpace free = scanFreeSpace(current, one.margin_m, one.margin_fraction);
  const common::Pose2 here = pose(k);
  for (size_t j = k > before ? k - before : 0; j < k; ++j) {
    if (!map.keyframes()[j].hasScan()) continue;
    io::LaserScan earlier = map.scan(j);
    if (earlier.size() == 0) continue;
    if (hideMovingReturns(earlier, {{&free, common::between(pose(j), here)}}, one) > 0) return true;
  }
  return false;
}

MovingReturns::MovingReturns(const MovingReturnsOptions& options, size_t cached_keyframes)
    // Room for every judge of one scan at least.
    : options_(options),
      judges_(options.margin_m, options.margin_fraction,
              std::max(cached_keyframes, 2 * static_cast<size_t>(std::max(0, options.neighbours)) + 1)) {}

io::LaserScan MovingReturns::scanWithout(const Map& map, size_t k, size_t newest, const std::function<common::Pose2(size_t)>& pose) {
  io::LaserScan scan = map.scan(k);
  if (options_.neighbours <= 0 || scan.size() == 0) return scan;
  if (map_ != &map) {  // another map's keyframe j is another scan
    judges_.clear();
    map_ = &map;
  }
  const auto& keyframes = map.keyframes();
  const common::Pose2 here = pose(k);
  // (Every judge's free space stays in the cache until the scan is judged: it holds more than
  // one scan's judges.)
  std::vector<ScanJudge> judges;
  const auto take = [&](size_t j) {
    if (!keyframes[j].hasScan()) return;
    const common::Pose2 rel = common::between(here, pose(j));
    if (!(std::hypot(rel.x, rel.y) <= options_.reach_m)) return;
    const auto scan_of = [&](io::LaserScan& buffer) -> const io::LaserScan& {
      map.scanInto(j, buffer);
      return buffer;
    };
    judges.push_back({&judges_.get(j, scan_of), rel});
  };
  const size_t n = static_cast<size_t>(options_.neighbours);
  for (size_t j = k > n ? k - n : 0; j < k; ++j) take(j);
  for (size_t j = k + 1; j <= std::min({k + n, newest, keyframes.size() - 1}); ++j) take(j);
  hideMovingReturns(scan, judges, options_);
  return scan;
}

}  // namespace urbanslam::slam
