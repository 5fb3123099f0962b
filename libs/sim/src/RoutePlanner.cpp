#include "urbanslam/sim/RoutePlanner.h"

#include <cmath>
#include <cstdlib>

namespace urbanslam::sim {

namespace {
constexpr uint64_t kTagRoute = 20;
}

RoutePlanner::RoutePlanner(const StreetGrid& grid, const RouteOptions& options, uint64_t seed)
    : grid_(grid), options_(options), rng_(hash64(seed, kTagRoute)) {
  // Start in the middle of the city, heading to a random neighbour.
  current_ = {grid.lineCount() / 2, grid.lineCount() / 2};
  const auto nb = grid.neighbours(current_);
  previous_ = nb.empty() ? current_ : nb[rng_.next() % nb.size()];
  history_.push_back(current_);
  budget_ = rng_.uniformInt(options.explore_min_edges, options.explore_max_edges);
}

NodeId RoutePlanner::advance() {
  auto options = grid_.neighbours(current_);
  std::vector<NodeId> forward;
  for (const NodeId& n : options)
    if (n != previous_) forward.push_back(n);
  if (forward.empty()) forward = options;  // cannot happen with the grid's dead-end rule

  if (budget_ <= 0 || (returning_ && current_ == target_)) {
    returning_ = false;
    if (history_.size() > 4 && rng_.chance(options_.revisit_probability)) {
      // Any earlier intersection: near ones give small loops, old ones large loops.
      target_ = history_[rng_.next() % (history_.size() - 3)];
      if (target_ != current_) {
        returning_ = true;
        ++revisits_;
        const int manhattan = std::abs(target_.i - current_.i) + std::abs(target_.j - current_.j);
        budget_ = 2 * manhattan + 6;  // gives up when dead ends make the greedy walk circle
      }
    }
    if (!returning_) budget_ = rng_.uniformInt(options_.explore_min_edges, options_.explore_max_edges);
  }

  NodeId next = forward[0];
  if (returning_) {
    const Vec2 goal = grid_.node(target_);
    double best = 1e300;
    for (const NodeId& n : forward) {
      const double d = norm(grid_.node(n) - goal) + rng_.uniform(0, 1.0);  // random tie breaks
      if (d < best) {
        best = d;
        next = n;
      }
    }
  } else {
    const NodeId straight{2 * current_.i - previous_.i, 2 * current_.j - previous_.j};
    std::vector<NodeId> turns;
    bool has_straight = false;
    for (const NodeId& n : forward) {
      if (n == straight) has_straight = true;
      else turns.push_back(n);
    }
    if (has_straight && (turns.empty() || rng_.chance(options_.straight_probability))) next = straight;
    else if (!turns.empty()) next = turns[rng_.next() % turns.size()];
  }
  --budget_;
  previous_ = current_;
  current_ = next;
  history_.push_back(current_);
  return current_;
}

}  // namespace urbanslam::sim
