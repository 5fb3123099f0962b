#include "urbanslam/sim/RoutePlanner.h"

#include <cmath>
#include <algorithm>
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
  // Forward: not back where we came from, and no hairpin turn off a diagonal avenue while a
  // gentler way exists.
  const Vec2 here = grid_.node(current_), back = grid_.node(previous_);
  const Vec2 d = here - back;
  auto turnAngle = [&](const NodeId& n) {
    const Vec2 e = grid_.node(n) - here;
    return std::fabs(std::atan2(cross(d, e), dot(d, e)));
  };
  std::vector<NodeId> forward, gentle;
  for (const NodeId& n : options)
    if (n != previous_) forward.push_back(n);
  if (forward.empty()) forward = options;  // cannot happen with the grid's dead-end rule
  if (current_ != previous_) {
    for (const NodeId& n : forward)
      if (turnAngle(n) < 125.0 * M_PI / 180.0) gentle.push_back(n);
    if (!gentle.empty()) forward = gentle;
  }

  if (budget_ <= 0 || (returning_ && current_ == target_)) {
    returning_ = false;
    if (history_.size() > 4 && rng_.chance(options_.revisit_probability)) {
      // Back to a recent intersection (a loop round a block or two), or to any earlier one (old
      // ones give loops of kilometres).
      const size_t older = history_.size() - 3;  // the last three are where the car just was
      if (rng_.chance(options_.small_loop_probability)) {
        const size_t back = 1 + rng_.next() % std::min<size_t>(8, older);
        target_ = history_[older - back];
      } else {
        target_ = history_[rng_.next() % older];
      }
      if (target_ != current_) {
        returning_ = true;
        ++revisits_;
        // Street pieces to get there (about one per grid pitch, along the grid), and some spare:
        // gives up when dead ends make the greedy walk circle.
        const Vec2 g = grid_.node(target_) - here;
        budget_ = 2 * static_cast<int>(std::lround((std::fabs(g.x) + std::fabs(g.y)) / grid_.pitch())) + 6;
      }
    }
    if (!returning_) budget_ = rng_.uniformInt(options_.explore_min_edges, options_.explore_max_edges);
  }

  NodeId next = forward[0];
  if (returning_) {
    const Vec2 goal = grid_.node(target_);
    double best = 1e300;
    for (const NodeId& n : forward) {
      const double dist = norm(grid_.node(n) - goal) + rng_.uniform(0, 1.0);  // random tie breaks
      if (dist < best) {
        best = dist;
        next = n;
      }
    }
  } else {
    // Straight on: the way out that turns least, if it hardly turns (avenue crossings included).
    std::vector<NodeId> turns;
    bool has_straight = false;
    NodeId straight{};
    double least = 20.0 * M_PI / 180.0;
    for (const NodeId& n : forward)
      if (current_ != previous_ && turnAngle(n) < least) {
        least = turnAngle(n);
        straight = n;
        has_straight = true;
      }
    for (const NodeId& n : forward)
      if (!has_straight || n != straight) turns.push_back(n);
    if (has_straight && (turns.empty() || rng_.chance(options_.straight_probability)))
      next = straight;
    else if (!turns.empty())
      next = turns[rng_.next() % turns.size()];
  }
  --budget_;
  previous_ = current_;
  current_ = next;
  history_.push_back(current_);
  return current_;
}

}  // namespace urbanslam::sim
