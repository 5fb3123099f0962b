#pragma once
// A point set thinned to one point per square voxel: the first point of each voxel, in the set's
// order. Local SLAM's search scores a scan thinned so (its points roughly independent), a place
// search searches one, and a loop closure's path submaps are built of them.
#include <cstddef>
#include <vector>

#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

// Indices into `points`, ascending: the first point of each voxel of side voxel_m.
std::vector<size_t> firstPerVoxel(const PointSet& points, double voxel_m);

}  // namespace urbanslam::alignment
