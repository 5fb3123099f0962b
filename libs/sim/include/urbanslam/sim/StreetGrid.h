#pragma once
// The street network of the simulated city: an irregular grid of jittered street lines. Every
// quantity (a line's position, whether a street piece is a dead end, whether a block is a park)
// is computed locally from hashes of the seed and the indices, so the network never has to be
// built as a whole and any tile of the city can be generated on its own.
//
// Vertical street lines sit at x = lineX(i), horizontal ones at y = lineY(j); the intersection
// (node) (i, j) is at (lineX(i), lineY(j)). Block (i, j) is the lot between lines i, i+1 and
// j, j+1. Lines 0 .. lineCount()-1 lie in the city; blocks exist one ring further out so that
// the streets on the city's edge have buildings on both sides.
#include <cstdint>
#include <vector>

#include "urbanslam/sim/CityOptions.h"
#include "urbanslam/sim/Geometry.h"

namespace urbanslam::sim {

struct NodeId {
  int i = 0, j = 0;
  bool operator==(const NodeId& o) const { return i == o.i && j == o.j; }
  bool operator!=(const NodeId& o) const { return !(*this == o); }
};

enum class EdgeState { Open, DeadEnd, Missing };

class StreetGrid {
 public:
  explicit StreetGrid(const CityOptions& options);

  int lineCount() const { return lines_; }
  double pitch() const { return pitch_; }
  double streetWidth() const { return width_; }
  double sidewalkWidth() const { return 0.15 * width_; }
  double parkingWidth() const { return 0.125 * width_; }
  // Distance of a driving lane's centre from the street's centre line.
  double laneOffset() const { return (width_ / 2 - sidewalkWidth() - parkingWidth()) / 2; }

  // axis 0: vertical lines (x positions), axis 1: horizontal lines (y positions). Defined for any
  // index, inside the city or not.
  double linePos(int axis, int index) const;
  // Largest index whose line is at or below v.
  int lineBelow(int axis, double v) const;

  Vec2 node(NodeId n) const { return {linePos(0, n.i), linePos(1, n.j)}; }
  bool inCity(NodeId n) const { return n.i >= 0 && n.j >= 0 && n.i < lines_ && n.j < lines_; }

  // The street piece from node (i, j) to (i+1, j) (axis 0, along x) or to (i, j+1) (axis 1).
  EdgeState edge(int axis, int i, int j) const;
  // For a dead end: true when the closed half is the one at the higher-index node.
  bool deadEndClosedAtEnd(int axis, int i, int j) const;
  // Intersections reachable from n in one street piece (open pieces only).
  std::vector<NodeId> neighbours(NodeId n) const;

  // The lot of block (i, j): between the facades of the surrounding streets.
  Box block(int i, int j) const;
  bool blockExists(int i, int j) const { return i >= -1 && j >= -1 && i < lines_ && j < lines_; }
  bool isPark(int i, int j) const;
  // Blocks that may have content within the box (index ranges, inclusive).
  void blocksNear(const Box& b, int& i0, int& i1, int& j0, int& j1) const;

  uint64_t seed() const { return seed_; }
  const CityOptions& options() const { return options_; }

 private:
  bool deadEndCandidate(int axis, int i, int j) const;

  CityOptions options_;
  uint64_t seed_;
  double width_, pitch_, jitter_;
  int lines_;
};

}  // namespace urbanslam::sim
