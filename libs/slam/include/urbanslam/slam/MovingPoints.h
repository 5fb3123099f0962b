#pragma once
// The map points of things that moved. A point that another keyframe's scan saw through (that
// scan's beams passed where the point was) was not there when that scan was taken: a passing
// car, a pedestrian, a door. A static world has no such point, so the test needs no model of
// what moves, and it judges a point only by scans that looked at its place. The point clouds
// leave these points out; the keyframes keep their scans whole (the .simplemap, the map file).
//
// Each keyframe's points are judged by the scans of up to `views` keyframes within `reach_m` of
// it, spread over the log in time (the same pass a second later, the pass before, a revisit
// much later), each scan's free space as BeamFreeSpace keeps it.
#include <vector>

#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/PointMask.h"

namespace urbanslam::slam {

struct MovingPointsOptions {
  double reach_m = 30;  // keyframes within this distance judge a keyframe's points
  int views = 16;       // at most this many of them
  int min_views = 2;    // a point seen through by this many has moved (one scan may be misplaced)
  // Seen through: the point lies this much in front of the returns of its bearing and both
  // neighbouring bearings (beam width, range noise, pose error) ...
  double margin_m = 0.3;
  double margin_fraction = 0.05;  // ... plus this share of their range
};

struct MovingPointsResult {
  io::PointMask static_points;  // the points of `scans` (cloud order) that stay
  size_t moving = 0;            // the points left out
  double seconds = 0;
};

MovingPointsResult findMovingPoints(const std::vector<io::PosedScan>& scans, const MovingPointsOptions& options);

}  // namespace urbanslam::slam
