#pragma once
// Which intersection comes next. Alternates exploring (random turns, a bias to go straight) with
// returning to an intersection visited earlier (greedy towards it), so the drive revisits streets
// in both directions and closes loops of many sizes. Deterministic from the seed.
#include <cstdint>
#include <vector>

#include "urbanslam/sim/Random.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/StreetGrid.h"

namespace urbanslam::sim {

class RoutePlanner {
 public:
  RoutePlanner(const StreetGrid& grid, const RouteOptions& options, uint64_t seed);

  NodeId current() const { return current_; }
  NodeId previous() const { return previous_; }
  // Moves to the next intersection and returns it.
  NodeId advance();
  size_t revisitsPlanned() const { return revisits_; }

 private:
  const StreetGrid& grid_;
  RouteOptions options_;
  Rng rng_;
  NodeId current_, previous_;
  std::vector<NodeId> history_;  // one entry per intersection passed (a drive of 1000 km: ~10^4)
  bool returning_ = false;
  NodeId target_;
  int budget_ = 0;  // street pieces left in the current mode
  size_t revisits_ = 0;
};

}  // namespace urbanslam::sim
