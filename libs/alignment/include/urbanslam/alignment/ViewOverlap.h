#pragma once
// How much of scan B an alignment onto scan A could ever explain, before aligning them.
//
// An alignment matches a point of B only where a point of A lies within the final association
// gate, and every point of A lies in A's field of view: the sector of its beams' bearings out to
// its longest return. So the share of B's points within the gate of that sector, at the pose the
// alignment ends at, bounds the share it can match. Over a whole region of poses (where the
// innovation gate would let a closure in) a branch and bound finds whether any pose of the region
// reaches a given share: a cell of poses is bounded by testing each point against the sector
// widened by how far the cell lets that point move. A 180° scanner that looked the other way, or
// pointed at a place the other never saw, cannot be aligned, and a global alignment (CRF-match
// and its ICP restarts: milliseconds) need not be tried.
#include <Eigen/Core>

#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/common/Pose2.h"

namespace urbanslam::alignment {

// The part of the plane a scan's points can lie in: bearings [mid - half, mid + half] from the
// sensor, ranges up to max_range_m. Everything when half_aperture_rad reaches pi.
struct ViewSector {
  common::Pose2 sensor_pose;  // sensor frame in the frame of the points
  double mid_rad = 0;
  double half_aperture_rad = 0;
  double max_range_m = 0;
  bool empty = true;  // no point: nothing can match
};

// The sector of a point set built by pointSetFromScan (its points keep their beams' range and
// bearing), whose points are in the frame in which the sensor sits at sensor_pose.
ViewSector viewSector(const PointSet& points, const common::Pose2& sensor_pose);

// The relative poses (pose of B in A's frame, as alignment returns it) within a Mahalanobis
// distance: (T - center)' cov^-1 (T - center) <= chi2, heading difference wrapped.
struct PoseRegion {
  common::Pose2 center;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  double chi2 = 11.34;  // 3 dof, 99 %
};

struct ViewOverlapOptions {
  double gate_m = 0.2;                   // the alignment's final association gate (IcpOptions::gate_final_m)
  double min_cell_heading_rad = 0.0017;  // cells are split down to this half-width in heading (0.1°)
  double min_cell_translation_m = 0.05;  // ... and in x and y
  int max_cells = 4000;                  // bounds examined at most; beyond, the answer is "maybe"
};

// Whether some pose of the region may put at least `share` of b's points within the gate of a's
// sector. False only when none can (a proof, not an estimate); true when one can or when the
// search gave up (a degenerate region, max_cells reached).
bool mayMatchShare(const ViewSector& a, const PointSet& b, const PoseRegion& region, double share, const ViewOverlapOptions& options = {});

// The share of b's points within the gate of a's sector at one pose (no widening): what
// mayMatchShare bounds over a region.
double shareInView(const ViewSector& a, const PointSet& b, const common::Pose2& b_in_a, double gate_m);

}  // namespace urbanslam::alignment
