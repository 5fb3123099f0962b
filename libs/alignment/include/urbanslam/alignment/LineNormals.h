#pragma once
// Line structure of a scan: the points are split, in sweep order, into straight pieces (greedy
// growth: a point joins the current piece while it lies within a tolerance of the piece's
// least-squares line and no range gap separates it), and every point of a piece gets the
// piece's normal. Fitting whole pieces rather than a few neighbours matters: a normal tilted by
// noise gives a wall spurious information along itself, which would make a corridor look
// constrained along its axis. A point gets no normal when its piece is too short (a corner,
// clutter, an isolated return): PL-ICP then falls back to point-to-point for it, and line
// variance gives it a full 2D covariance.
#include <vector>

#include <Eigen/Core>

#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

struct LineNormalOptions {
  double line_tolerance_m = 0.05;        // a point farther than this from the piece's line ends it
  double max_gap_m = 0.5;                // consecutive points farther apart belong to different objects
  double max_gap_range_fraction = 0.25;  // ... unless adjacent beams closer than this fraction of
                                         // the range (sparse far / grazing beams, one surface)
  int min_points = 3;                    // a piece needs this many points ...
  double min_length_m = 0.1;             // ... and this extent to define a normal
};

struct LineNormal {
  Eigen::Vector2d n = Eigen::Vector2d::Zero();  // unit normal (sign arbitrary)
  double residual_var_m2 = 0;                   // variance of the piece's points about its line
  int piece = -1;                               // index of the straight piece (-1: none)
  bool valid = false;
};

std::vector<LineNormal> computeLineNormals(const PointSet& points, const LineNormalOptions& options);

// A surface is seen from its front only. A point seen from `other_sensor` can be on the line of
// reference point `ref` (its `normal`) unless the two sensors are on opposite sides of that line,
// each seeing it more steeply than `grazing_rad` (seen nearly edge-on, a normal tilted by noise
// may put a sensor just behind it). Two views from opposite sides would otherwise pair the faces
// that each sees of the same things (a facade's pillars, the two halves of a post), which lie
// apart: two views of a street from its two ends then slide along it by a pillar's width. A point
// without a normal, or a negative tolerance: true.
bool seenFromSameSide(const LineNormal& normal, const ScanPoint& ref, const Eigen::Vector2d& other_sensor, double grazing_rad);

}  // namespace urbanslam::alignment
