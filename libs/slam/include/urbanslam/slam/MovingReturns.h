#pragma once
// The returns of a keyframe's scan that hit something which moved while the vehicle passed (a
// car in traffic, a pedestrian): the scans just before and after it in the log saw through
// their places. A loop closure aligns its two scans without them. Two visits that each saw a
// car at about the same distance ahead (queuing at the same lights, the oncoming lane) align
// on the cars otherwise, along a street whose facades hardly tell where along it the scans
// were: such pairs were the false closures of the 1,000 km city drive (bench/scale/RESULTS.md).
//
// The seen-through test of MovingPoints.h (which cleans the exported clouds with every keyframe
// around a place), judged here by a few keyframes next to the scan in the log: cheap enough for
// every closure attempt, and no second visit needed. A car moving away from the vehicle is
// seen through by the scans after it, an oncoming one by the scans before it too.
#include <cstddef>
#include <functional>
#include <vector>

#include "urbanslam/alignment/BeamFreeSpace.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/slam/FreeSpaceCache.h"

namespace urbanslam::slam {

class Map;

struct MovingReturnsOptions {
  int neighbours = 5;   // judges: the keyframes with scans up to this many places before and after in the log
  int min_views = 2;    // a return seen through by this many judges moved (one may be misplaced)
  double reach_m = 30;  // a judge farther than this from the scan says nothing (another session)
  // Seen through: the return lies this much in front of the judge's returns of its bearing and
  // both neighbouring bearings (beam width, range noise, pose error) ...
  double margin_m = 0.3;
  double margin_fraction = 0.05;  // ... plus this share of their range
  double min_width_m = 1.0;       // hidden only in runs of returns at least this wide (a vehicle)
};

// A scan that judges another: the space its beams passed through (scanFreeSpace with the
// options' margins, FreeSpaceCache.h), and its vehicle pose in the judged scan's vehicle frame.
struct ScanJudge {
  const alignment::BeamFreeSpace* free = nullptr;
  common::Pose2 pose;
};

// Marks invalid the returns of `scan` that at least min_views of the judges saw through, in
// runs of beams (none missing, or one at a time) whose ends lie min_width_m apart or more;
// returns how many.
size_t hideMovingReturns(io::LaserScan& scan, const std::vector<ScanJudge>& judges, const MovingReturnsOptions& options);

// Whether keyframe k's scan sees through a run of returns (min_width_m or more) of one of the
// `before` keyframes before it, each placed by `pose`: something there moved (a car ahead that
// drove on) and may still be in k's view, where only the keyframes after k see through it.
bool seesThroughEarlier(const Map& map, size_t k, size_t before, const std::function<common::Pose2(size_t)>& pose,
                        const MovingReturnsOptions& options);

// A map's keyframe scans without their moving returns. The judges' free space is kept for the
// keyframes used lately (a keyframe's scan never changes): consecutive closure attempts judge
// neighbouring keyframes, which share most of their judges.
class MovingReturns {
 public:
  explicit MovingReturns(const MovingReturnsOptions& options, size_t cached_keyframes = 64);
  // Keyframe k's scan with its moving returns hidden, judged by the keyframes with scans within
  // `neighbours` places of k in the log, none after `newest` (what exists when k's closures are
  // sought does not depend on how far local SLAM has run ahead), placed by `pose` (the estimate).
  io::LaserScan scanWithout(const Map& map, size_t k, size_t newest, const std::function<common::Pose2(size_t)>& pose);

 private:
  MovingReturnsOptions options_;
  const Map* map_ = nullptr;  // the map whose keyframes `judges_` holds
  FreeSpaceCache judges_;
};

}  // namespace urbanslam::slam
