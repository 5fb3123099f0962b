#pragma once
// Ground-truth loop pairs: two scans far apart in time whose views overlap. Overlap is the
// fraction of the newer scan's beam end points (world frame, true poses) that have an end point
// of the older scan within match_radius_m. Candidates come from a spatial hash of the sensor
// positions, so a drive costs O(n * revisits), not O(n^2); each scan keeps its points sorted
// along x, so a pair costs O(points * log points).
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "urbanslam/io/LaserScan.h"
#include "urbanslam/sim/Geometry.h"
#include "urbanslam/sim/SimOptions.h"

namespace urbanslam::sim {

// Key of the square cell of side `cell_m` holding (x, y): the spatial hash both loop-truth
// finders (scans here, images in ImageLoopTruth.h) look up sensor positions in.
int64_t positionCellKey(double x, double y, double cell_m);

struct LoopPair {
  double t_old = 0, t_new = 0;
  double overlap = 0;     // fraction in [0, 1]
  double distance_m = 0;  // between the sensor positions
};

class LoopTruthFinder {
 public:
  explicit LoopTruthFinder(const LoopTruthOptions& options);
  // Adds a scan taken at the true vehicle pose and returns the pairs it forms with earlier scans.
  std::vector<LoopPair> add(const io::LaserScan& scan, const common::Pose2& vehicle);
  // The same for any sensor: what it saw as wall points (world frame) from its position.
  std::vector<LoopPair> add(double t, Vec2 sensor, const std::vector<Vec2>& points);

  // The beam end points the overlap is computed from: every point_stride-th beam, if valid.
  static std::vector<Vec2> endPoints(const io::LaserScan& scan, const common::Pose2& vehicle, int stride);

 private:
  struct Entry {
    double t;
    Vec2 sensor;
    std::vector<float> xy;  // end points, interleaved (floats: half the memory of a long drive), sorted by x
    std::array<float, 2> min_y_max_y;  // their extent across x
  };

  LoopTruthOptions options_;
  std::vector<Entry> scans_;
  std::unordered_map<int64_t, std::vector<uint32_t>> cells_;
};

}  // namespace urbanslam::sim
