#pragma once
// The content of one block (building outlines with facade detail, or a park/square) and of the
// sidewalks around it (trees, lamp posts, parked cars), and the wall that closes a dead end.
// Pure functions of the street grid's seed and the indices: a tile is built from the blocks it
// overlaps, in any order, with identical results.
#include <vector>

#include "urbanslam/sim/Geometry.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

void generateBlock(const StreetGrid& grid, int i, int j, std::vector<Segment>& out);

// The closed half of the dead-end street piece (axis, i, j): a closed outline across the street.
void generateDeadEnd(const StreetGrid& grid, int axis, int i, int j, std::vector<Segment>& out);

}  // namespace urbanslam::sim
