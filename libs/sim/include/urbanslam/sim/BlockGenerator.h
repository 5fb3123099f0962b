#pragma once
// The content of one block (several buildings with facade detail and alleys between them, cut
// back where a diagonal avenue crosses the block or a roundabout needs its corner; or a park, or
// a paved square) and of the sidewalks around it (trees, lamp posts, parked cars), the wall that
// closes a dead end, and a roundabout's island.
// Pure functions of the street grid's seed and the indices: a tile is built from the blocks it
// overlaps, in any order, with identical results.
#include <vector>

#include "urbanslam/sim/Geometry.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

void generateBlock(const StreetGrid& grid, int i, int j, std::vector<Segment>& out);

// The closed half of the dead-end street piece (axis, i, j): a closed outline across the street.
void generateDeadEnd(const StreetGrid& grid, int axis, int i, int j, std::vector<Segment>& out);

// The island of the roundabout at grid node n: a round kerb.
void generateRoundabout(const StreetGrid& grid, NodeId n, std::vector<Segment>& out);

}  // namespace urbanslam::sim
