#pragma once
// Free-space consistency of an alignment (negative information): a point of one scan must not
// lie where the other scan's beams passed through empty space. A wrong loop closure in a
// corridor or along a facade can match most points of both scans (same walls, slid by a door
// spacing) and still put a wall across a room or a doorway the other scan saw through; a true
// one leaves only people and doors that moved.
#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::alignment {

struct FreeSpaceOptions {
  // A point conflicts when it lies this much in front of where the other scan's beams ended:
  // margin_m + margin_fraction * that range (beam divergence, range noise, alignment error).
  double margin_m = 0.3;
  double margin_fraction = 0.05;
  double min_range_m = 0.2;  // beams shorter than this see nothing useful (the robot itself)
  // A beam with no return (at or beyond the sensor's or the configured maximum range) saw free
  // space up to this distance: outdoors most of a scan is sky and open ground. 0: a no-return
  // says nothing (glass and black surfaces also return nothing).
  double no_return_free_m = 0;
};

struct FreeSpaceConflict {
  int tested = 0;     // points that fell inside the other scan's field of view, on returns
  int conflicts = 0;  // of those, points inside the other scan's free space
  double fraction() const { return tested > 0 ? static_cast<double>(conflicts) / tested : 0.0; }
};

// Points of `b`, placed at `b_in_a` (pose of B's vehicle frame in A's, as alignment::align
// returns it), tested against the free space seen by `a`. A point is tested only where `a`'s
// beam and both its neighbours are returns: a no-return says nothing certain about free space.
FreeSpaceConflict freeSpaceConflict(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& b_in_a,
                                    const FreeSpaceOptions& options = {});

// Both ways (b against a's free space, a against b's): the larger conflicting fraction.
double mutualFreeSpaceConflict(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& b_in_a,
                               const FreeSpaceOptions& options = {});

}  // namespace urbanslam::alignment
