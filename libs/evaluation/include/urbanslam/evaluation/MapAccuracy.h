#pragma once
// Accuracy of a map against the true walls it was built from (a simulated city's walls.csv):
// the distance of every map point to the nearest true wall. A map can have a small trajectory
// error and still be blurred (wrong scan matches between keyframes) or doubled (a missed
// closure); this is what a user who measures the map sees.
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::evaluation {

struct WallSegment {
  double x1 = 0, y1 = 0, x2 = 0, y2 = 0;
};

// walls.csv: header "x1,y1,x2,y2", one segment per line. Throws common::InputError naming file
// and line.
std::vector<WallSegment> readWallsCsv(const std::string& path);

struct MapAccuracyMetrics {
  size_t points = 0;  // map points scored
  double mean_m = 0, median_m = 0, p95_m = 0;
  double within_0_1_m = 0;  // fraction of points within 0.1 m of a wall
  double beyond_1_m = 0;    // fraction farther than 1 m (moving objects, or a broken map)
};

// `to_truth` carries the map's frame into the walls' (e.g. the ATE's rigid alignment). Distances
// are capped at cap_m (a point with no wall within reach counts as cap_m).
MapAccuracyMetrics mapAccuracy(const std::vector<io::MapPoint>& points, const common::Pose2& to_truth,
                               const std::vector<WallSegment>& walls, double cap_m = 5.0);

// True revisits closed: a true loop pair (t_old, t_new) (the simulator's loops.csv: two scans
// far apart in time whose views overlap) is closed when an accepted closure joins times within
// tolerance_s of both. Reported per revisited scan (t_new), so a long revisit weighs by its
// length.
struct TrueLoop {
  double t_old = 0, t_new = 0;
};
std::vector<TrueLoop> readTrueLoopsCsv(const std::string& path);

struct LoopRecall {
  size_t revisited_scans = 0, closed_scans = 0;
  double recall = 0;
};
struct LoopRow;
LoopRecall loopRecall(const std::vector<LoopRow>& closures, const std::vector<TrueLoop>& truth, double tolerance_s = 2.0);

// True revisits closed, counted per revisit rather than per scan: the revisited scans (t_new) in
// runs with no gap over max_gap_s, each as long as the path the truth drove along it
// (`truth_path`, by time). A revisit of at least min_path_m is closed when an accepted closure
// joins one of its pairs (as loopRecall). Whatever the drift when it began, a closed revisit was
// found, by the estimate or by appearance; an unclosed one is a loop the map never tied.
struct Revisit {
  double t_start = 0, t_end = 0, path_m = 0;
  bool closed = false;
};
struct RevisitRecall {
  size_t revisits = 0, closed = 0;
  std::vector<Revisit> unclosed;
};
RevisitRecall revisitRecall(const std::vector<LoopRow>& closures, const std::vector<TrueLoop>& truth,
                            const std::vector<io::StampedPose>& truth_path, double min_path_m = 50.0, double max_gap_s = 1.0,
                            double tolerance_s = 2.0);

}  // namespace urbanslam::evaluation
