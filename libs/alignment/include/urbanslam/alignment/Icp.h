#pragma once
// Iterative closest point (thesis §3.3.1; Besl & McKay 1992): each point of the moving scan is
// associated with its nearest neighbour in the reference scan (kd-tree), pairs farther apart
// than a distance gate are disregarded, the closed-form 2D least-squares rotation + translation
// of the pairs is applied, and the procedure repeats with a progressively smaller gate.
//
// Point-to-line ICP (Censi 2008) is the same loop with a different error: the distance of the
// moving point to the reference point's local line (LineNormals.h), minimised by Gauss-Newton.
// It converges in fewer iterations on structured scenes because sliding along walls is free.
//
// Both accept a robust kernel (iteratively reweighted least squares) against the pairs that the
// gate lets through but that are still wrong (clutter, moved objects, partial overlap).
#include "urbanslam/alignment/LineNormals.h"
#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/alignment/Registration.h"

namespace urbanslam::alignment {

enum class RobustKernel { None, Huber, Cauchy };

struct IcpOptions {
  double gate_initial_m = 4.0;  // association gate of the first iterations (bench: 4 m beats
                                // 1.5 and 2.5 m from initial errors of 1-2 m)
  double gate_final_m = 0.2;    // smallest gate; must exceed noise + beam spacing
  double gate_shrink = 0.6;     // gate *= this each time the estimate settles at a gate
  int max_iterations = 60;
  double tolerance_m = 1e-4;  // an update smaller than this (and tolerance_rad) has settled
  double tolerance_rad = 1e-4;
  // The kernel weights pairs only at the final gate (see Icp.cpp). Applied at every gate it
  // cost success on the Freiburg pairs (PL-ICP from 1 m / 30 deg: none 84 %, Cauchy 73 %).
  RobustKernel kernel = RobustKernel::Cauchy;
  double kernel_scale_m = 0.05;  // residual at which the kernel starts to discount a pair
  int min_matches = 8;           // fewer pairs than this: no solution
  double min_overlap = 0.25;     // fraction of moving points matched at the final gate
  // A caller that accepts only alignments matching this fraction of the moving points at the
  // final gate: a run that settles at a gate of abandon_gate_factor final gates or less with
  // fewer points than that within it is given up there (it would need to gain matches while
  // its gate shrinks to a fifth; on the 1 km² city's loop candidates none of 3242 runs that
  // ended above the fraction was below it there, and the runs given up saved a third of the
  // iterations). 0: never.
  double abandon_below_fraction = 0;
  double abandon_gate_factor = 5;
  LineNormalOptions normals;  // point-to-line only
  // Point-to-line: a moving point is not paired with a reference line when the two sensors see
  // that line from opposite sides, each more steeply than this (LineNormals.h,
  // seenFromSameSide); < 0: it always is.
  double seen_side_tolerance_deg = 10;
};

class NearestNeighbours;

// Point-to-point ICP of `moving` onto `reference`, starting from `guess`.
RegistrationResult icp(const PointSet& reference, const PointSet& moving, const common::Pose2& guess, const IcpOptions& options);

// Point-to-line ICP.
RegistrationResult plIcp(const PointSet& reference, const PointSet& moving, const common::Pose2& guess, const IcpOptions& options);

// The shared loop, for callers that run many alignments against one reference (sampling
// covariance): a prebuilt index of the reference and its normals (one per reference point;
// empty = point-to-point).
RegistrationResult icpWithIndex(const PointSet& reference, const NearestNeighbours& index, const std::vector<LineNormal>& normals,
                                const PointSet& moving, const common::Pose2& guess, const IcpOptions& options);

}  // namespace urbanslam::alignment
