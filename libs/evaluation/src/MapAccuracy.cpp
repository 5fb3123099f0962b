#include "urbanslam/evaluation/MapAccuracy.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/evaluation/Evaluation.h"

namespace urbanslam::evaluation {

namespace {

// Numeric CSV rows after a header line, each with at least `columns` values.
std::vector<std::vector<double>> readNumericCsv(const std::string& path, size_t columns) {
  std::ifstream in(path);
  if (!in) throw common::InputError(path + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::string line;
  std::getline(in, line);  // header
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    try {
      while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    } catch (const std::exception&) {
      throw common::InputError(path + ":" + std::to_string(n) + ": malformed number");
    }
    if (row.size() < columns || !std::all_of(row.begin(), row.end(), [](double v) { return std::isfinite(v); }))
      throw common::InputError(path + ":" + std::to_string(n) + ": expected " + std::to_string(columns) + " finite numbers");
    rows.push_back(std::move(row));
  }
  return rows;
}

double pointSegmentDistance(double px, double py, const WallSegment& s) {
  const double dx = s.x2 - s.x1, dy = s.y2 - s.y1, l2 = dx * dx + dy * dy;
  const double u = l2 > 0 ? std::clamp(((px - s.x1) * dx + (py - s.y1) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(px - (s.x1 + u * dx), py - (s.y1 + u * dy));
}

// Segments bucketed in square cells along their length, so a query looks at the few walls near
// a point instead of all of a city's.
class WallIndex {
 public:
  WallIndex(const std::vector<WallSegment>& walls, double cell_m) : walls_(walls), cell_(cell_m) {
    for (size_t i = 0; i < walls.size(); ++i) {
      const WallSegment& s = walls[i];
      const double len = std::hypot(s.x2 - s.x1, s.y2 - s.y1);
      const int steps = std::max(1, static_cast<int>(std::ceil(2 * len / cell_)));
      long long last = 0;
      for (int k = 0; k <= steps; ++k) {
        const double u = static_cast<double>(k) / steps;
        const long long key = keyOf(cellOf(s.x1 + u * (s.x2 - s.x1)), cellOf(s.y1 + u * (s.y2 - s.y1)));
        if (k > 0 && key == last) continue;
        auto& bucket = cells_[key];
        if (bucket.empty() || bucket.back() != i) bucket.push_back(i);
        last = key;
      }
    }
  }

  // Distance to the nearest wall, at most cap_m.
  double nearest(double x, double y, double cap_m) const {
    const long long cx = cellOf(x), cy = cellOf(y);
    double best = cap_m;
    const int rings = static_cast<int>(std::ceil(cap_m / cell_));
    for (int r = 0; r <= rings; ++r) {
      // Every cell of ring r is at least (r - 1) cells from the point.
      if ((r - 1) * cell_ > best) break;
      for (long long i = cx - r; i <= cx + r; ++i)
        for (long long j = cy - r; j <= cy + r; ++j) {
          if (std::max(std::llabs(i - cx), std::llabs(j - cy)) != r) continue;
          const auto it = cells_.find(keyOf(i, j));
          if (it == cells_.end()) continue;
          for (size_t k : it->second) best = std::min(best, pointSegmentDistance(x, y, walls_[k]));
        }
    }
    return best;
  }

 private:
  long long cellOf(double v) const { return static_cast<long long>(std::floor(v / cell_)); }
  // Shifted unsigned: a left shift of a negative value is undefined behaviour.
  static long long keyOf(long long i, long long j) {
    return static_cast<long long>(static_cast<unsigned long long>(i) << 32) ^ (j & 0xffffffffLL);
  }

  const std::vector<WallSegment>& walls_;
  double cell_;
  std::unordered_map<long long, std::vector<size_t>> cells_;
};

}  // namespace

std::vector<WallSegment> readWallsCsv(const std::string& path) {
  std::vector<WallSegment> out;
  for (const auto& r : readNumericCsv(path, 4)) out.push_back({r[0], r[1], r[2], r[3]});
  return out;
}

MapAccuracyMetrics mapAccuracy(const std::vector<io::MapPoint>& points, const common::Pose2& to_truth,
                               const std::vector<WallSegment>& walls, double cap_m) {
  MapAccuracyMetrics m;
  if (points.empty() || walls.empty()) return m;
  const WallIndex index(walls, 1.0);
  const double c = std::cos(to_truth.phi), s = std::sin(to_truth.phi);
  std::vector<double> d;
  d.reserve(points.size());
  for (const auto& p : points) d.push_back(index.nearest(to_truth.x + c * p.x - s * p.y, to_truth.y + s * p.x + c * p.y, cap_m));
  m.points = d.size();
  double sum = 0;
  size_t near = 0, far = 0;
  for (double v : d) {
    sum += v;
    near += v <= 0.1 ? 1 : 0;
    far += v > 1.0 ? 1 : 0;
  }
  const double n = static_cast<double>(d.size());
  m.mean_m = sum / n;
  m.within_0_1_m = near / n;
  m.beyond_1_m = far / n;
  m.median_m = common::percentile(d, 50);
  m.p95_m = common::percentile(std::move(d), 95);
  return m;
}

std::vector<TrueLoop> readTrueLoopsCsv(const std::string& path) {
  std::vector<TrueLoop> out;
  for (const auto& r : readNumericCsv(path, 2)) out.push_back({r[0], r[1]});
  return out;
}

namespace {
// Each revisited scan (its time in ms) and whether an accepted closure joins one of its pairs.
std::unordered_map<long long, bool> closedScans(const std::vector<LoopRow>& closures, const std::vector<TrueLoop>& truth,
                                                double tolerance_s) {
  // The accepted closures by their later time, to find those near a revisited scan quickly.
  std::vector<std::pair<double, double>> accepted;  // (later time, earlier time)
  for (const auto& c : closures)
    if (c.accepted) accepted.push_back({std::max(c.from_time, c.to_time), std::min(c.from_time, c.to_time)});
  std::sort(accepted.begin(), accepted.end());
  std::unordered_map<long long, bool> scans;  // revisited scan (ms) -> closed
  for (const auto& t : truth) {
    const long long key = std::llround(t.t_new * 1000);
    bool& closed = scans[key];
    if (closed) continue;
    auto it = std::lower_bound(accepted.begin(), accepted.end(), std::make_pair(t.t_new - tolerance_s, -1e300));
    for (; it != accepted.end() && it->first <= t.t_new + tolerance_s; ++it)
      if (std::abs(it->second - t.t_old) <= tolerance_s) {
        closed = true;
        break;
      }
  }
  return scans;
}
}  // namespace

RevisitRecall revisitRecall(const std::vector<LoopRow>& closures, const std::vector<TrueLoop>& truth,
                            const std::vector<io::StampedPose>& truth_path, double min_path_m, double max_gap_s, double tolerance_s) {
  const auto scans = closedScans(closures, truth, tolerance_s);
  std::vector<std::pair<long long, bool>> ordered(scans.begin(), scans.end());
  std::sort(ordered.begin(), ordered.end());
  // The path the truth drove between two times.
  const auto pathBetween = [&](double t0, double t1) {
    const auto at = [](const io::StampedPose& p, double t) { return p.timestamp < t; };
    auto it = std::lower_bound(truth_path.begin(), truth_path.end(), t0, at);
    double length = 0;
    for (; it != truth_path.end() && std::next(it) != truth_path.end() && std::next(it)->timestamp <= t1; ++it)
      length += std::hypot(std::next(it)->pose.x - it->pose.x, std::next(it)->pose.y - it->pose.y);
    return length;
  };
  RevisitRecall r;
  for (size_t i = 0; i < ordered.size();) {
    Revisit v;
    v.t_start = v.t_end = 1e-3 * static_cast<double>(ordered[i].first);
    size_t j = i;
    for (; j < ordered.size() && 1e-3 * static_cast<double>(ordered[j].first) - v.t_end <= max_gap_s; ++j) {
      v.t_end = 1e-3 * static_cast<double>(ordered[j].first);
      v.closed = v.closed || ordered[j].second;
    }
    i = j;
    v.path_m = pathBetween(v.t_start, v.t_end);
    if (v.path_m < min_path_m) continue;
    ++r.revisits;
    if (v.closed)
      ++r.closed;
    else
      r.unclosed.push_back(v);
  }
  return r;
}

LoopRecall loopRecall(const std::vector<LoopRow>& closures, const std::vector<TrueLoop>& truth, double tolerance_s) {
  const auto scans = closedScans(closures, truth, tolerance_s);
  LoopRecall r;
  r.revisited_scans = scans.size();
  for (const auto& [k, closed] : scans) r.closed_scans += closed ? 1 : 0;
  r.recall = r.revisited_scans ? static_cast<double>(r.closed_scans) / static_cast<double>(r.revisited_scans) : 0.0;
  return r;
}

}  // namespace urbanslam::evaluation
