#pragma once
// The street network of the simulated city: an irregular grid of jittered street lines, crossed
// by a few straight diagonal avenues, with roundabouts at some of the grid's intersections. Every
// quantity (a line's position, an avenue's crossings, whether a street piece is a dead end,
// whether a block is a park or a square, whether an intersection is a roundabout) is computed
// locally from hashes of the seed and the indices, so the network never has to be built as a
// whole and any tile of the city can be generated on its own.
//
// Vertical street lines sit at x = lineX(i), horizontal ones at y = lineY(j); the intersection
// (node) (i, j) is at (lineX(i), lineY(j)). Block (i, j) is the lot between lines i, i+1 and
// j, j+1. Lines 0 .. lineCount()-1 lie in the city; blocks exist one ring further out so that
// the streets on the city's edge have buildings on both sides.
//
// Avenues are parallel lines dot(p, avenueNormal()) = avenueOffset(a), one every
// avenue_spacing_m, crossing the whole city (they end at its edge streets). Where one crosses a
// grid line it makes an intersection of its own, unless it passes so close to a grid
// intersection that the two are one: then the avenue runs through that grid node.
#include <cstdint>
#include <vector>

#include "urbanslam/sim/CityOptions.h"
#include "urbanslam/sim/Geometry.h"

namespace urbanslam::sim {

// kind 0: the grid intersection (i, j). kind 1 / 2: where avenue i crosses the vertical line j
// (kind 1) or the horizontal line j (kind 2).
struct NodeId {
  int i = 0, j = 0, kind = 0;
  bool operator==(const NodeId& o) const { return i == o.i && j == o.j && kind == o.kind; }
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
  // The kerb: half the width of the carriageway (parking and driving lanes).
  double roadwayHalfWidth() const { return width_ / 2 - sidewalkWidth(); }

  // axis 0: vertical lines (x positions), axis 1: horizontal lines (y positions). Defined for any
  // index, inside the city or not.
  double linePos(int axis, int index) const;
  // Largest index whose line is at or below v.
  int lineBelow(int axis, double v) const;
  // The city's extent between its edge streets' centre lines.
  Box cityBox() const;

  Vec2 node(NodeId n) const;
  bool inCity(NodeId n) const { return n.i >= 0 && n.j >= 0 && n.i < lines_ && n.j < lines_; }

  // The grid's street piece from node (i, j) to (i+1, j) (axis 0, along x) or to (i, j+1)
  // (axis 1), as a street (an avenue crossing it does not change its state).
  EdgeState edge(int axis, int i, int j) const;
  // For a dead end: true when the closed half is the one at the higher-index node.
  bool deadEndClosedAtEnd(int axis, int i, int j) const;
  // Intersections reachable from n along one street piece or avenue piece (open pieces only).
  std::vector<NodeId> neighbours(NodeId n) const;
  // Half the width (facade to facade) of the street or avenue piece between two neighbours.
  double pieceHalfWidth(NodeId a, NodeId b) const;
  // Right-hand lane's centre from the centre line of that piece.
  double pieceLaneOffset(NodeId a, NodeId b) const;

  // Avenues.
  bool hasAvenues() const { return avenue_spacing_ > 0; }
  Vec2 avenueDirection() const { return avenue_u_; }
  Vec2 avenueNormal() const { return avenue_n_; }
  double avenueOffset(int a) const { return avenue_phase_ + a * avenue_spacing_; }
  double avenueHalfWidth() const { return options_.avenue_width_m / 2; }
  // Signed distance of p from avenue a's centre line.
  double avenueDistance(int a, Vec2 p) const { return dot(p, avenue_n_) - avenueOffset(a); }
  // Avenues whose centre line passes within `margin` of the box (index range, empty if a0 > a1).
  void avenuesNear(const Box& b, double margin, int& a0, int& a1) const;
  // Inside the carriageway-to-facade strip of an avenue, within the city (grown by margin).
  bool inAvenue(Vec2 p, double margin = 0) const;

  // Roundabouts: a circular island at a grid node, driven round counter-clockwise (right-hand
  // traffic). Island, the centre line of the ring lane, the ring's outer kerb, and the radius
  // kept free of buildings.
  bool isRoundabout(NodeId n) const;
  double islandRadius() const { return options_.roundabout_island_radius_m; }
  double ringRadius() const { return islandRadius() + 3.5; }
  double ringOuterRadius() const { return islandRadius() + 7.0; }
  double roundaboutClearRadius() const { return ringOuterRadius() + sidewalkWidth(); }
  // Within radius of a roundabout's centre (checks the nearest grid node).
  bool nearRoundabout(Vec2 p, double radius) const;

  // The lot of block (i, j): between the facades of the surrounding grid streets.
  Box block(int i, int j) const;
  bool blockExists(int i, int j) const { return i >= -1 && j >= -1 && i < lines_ && j < lines_; }
  bool blockInCity(int i, int j) const { return i >= 0 && j >= 0 && i < lines_ - 1 && j < lines_ - 1; }
  bool isPark(int i, int j) const;
  bool isSquare(int i, int j) const;
  // Blocks that may have content within the box (index ranges, inclusive).
  void blocksNear(const Box& b, int& i0, int& i1, int& j0, int& j1) const;

  uint64_t seed() const { return seed_; }
  const CityOptions& options() const { return options_; }

 private:
  bool deadEndCandidate(int axis, int i, int j) const;
  // Where avenue a crosses grid line (axis, l), if inside the city.
  bool rawCrossing(int a, int axis, int l, Vec2& p) const;
  // The node that crossing is: its own, or the grid node it merges with.
  NodeId crossingNode(int a, int axis, int l) const;
  bool onAvenue(int a, NodeId n) const;
  // The next node along avenue a from n (dir +1 / -1 along avenueDirection()); false: the end.
  bool avenueStep(int a, NodeId n, int dir, NodeId& next) const;
  // The node an avenue splits the grid piece with (the one nearest `from`), if any.
  bool pieceSplit(int axis, int i, int j, NodeId from, NodeId& split) const;
  double mergeRadius() const { return 0.2 * avenueHalfWidth(); }

  CityOptions options_;
  uint64_t seed_;
  double width_, pitch_, jitter_;
  int lines_;
  double avenue_spacing_ = 0, avenue_phase_ = 0;
  Vec2 avenue_u_{1, 0}, avenue_n_{0, 1};
};

}  // namespace urbanslam::sim
