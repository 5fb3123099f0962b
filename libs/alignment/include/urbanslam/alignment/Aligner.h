#pragma once
// The one alignment call that the pipeline (loop closures, laser odometry) and `urbanslam align`
// use: scan B aligned onto scan A, i.e. the pose of B seen from A (common::between(pose_A,
// pose_B)), with its covariance, starting from a guess in the same convention.
//
// Methods: "prior" (the guess as a prior with prior_sigma: correlative search over its window,
// then point-to-line least squares with the prior term: PriorScanMatcher.h, local SLAM's
// matcher), "icp" (point-to-point, thesis §3.3.1), "plicp" (point-to-line), "crf" (CRF-match,
// §3.3.2) and "crf+icp" (CRF-match for the coarse alignment, ICP to refine, as in the thesis;
// the refinement also runs from CRF-match's other hypotheses and from the guess, and the one
// that matches most points wins).
// Failures (too few points, NaN input, no agreement, degenerate geometry such as a corridor) come
// back with converged = false and a failure_reason; the transform is then the best available
// estimate (the guess when nothing could be computed) and must not be used as a measurement.
#include <string>

#include <Eigen/Core>

#include "urbanslam/alignment/AlignmentCovariance.h"
#include "urbanslam/alignment/CrfMatch.h"
#include "urbanslam/alignment/Icp.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/PriorScanMatcher.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::alignment {

enum class Method { Prior, Icp, PlIcp, Crf, CrfIcp };

struct AlignerOptions {
  Method method = Method::CrfIcp;
  ScanModelOptions scan;
  IcpOptions icp;
  bool refine_point_to_line = true;  // crf+icp refines with PL-ICP (else point-to-point ICP)
  CrfOptions crf;
  CovarianceOptions covariance;
  double min_constraint_ratio = 0.01;  // below: the geometry leaves a direction free (degenerate)
  bool in_vehicle_frame = true;        // LaserScan input: apply sensor_pose (vehicle relative pose)
  PriorMatcherOptions prior;           // method prior
  double prior_sigma_m = 0.5;          // method prior: how far off the guess may be (1 sigma, x and y)
  double prior_sigma_deg = 15.0;       // ... and its heading
};

struct AlignmentResult {
  common::Pose2 transform;                                  // pose of B in A's frame
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity() * 1e4;  // (x, y, phi)
  int iterations = 0;                                       // ICP iterations (+ BP iterations for CRF)
  double time_ms = 0;                                       // whole call, covariance included
  double covariance_time_ms = 0;
  bool converged = false;
  std::string failure_reason;  // empty when converged
  int matches = 0;             // associations at the final transform
  double rms_residual_m = 0;
  double constraint_ratio = 0;     // translationConstraintRatio at the result
  int points_a = 0, points_b = 0;  // after the scan model's gates
  // Share of B's points associated at the result (how much of the scan the match explains).
  double matchedFraction() const { return points_b > 0 ? static_cast<double>(matches) / points_b : 0.0; }
};

AlignmentResult align(const io::LaserScan& a, const io::LaserScan& b, const common::Pose2& guess, const AlignerOptions& options);
AlignmentResult alignPointSets(const PointSet& a, const PointSet& b, const common::Pose2& guess, const AlignerOptions& options);
// The same with A's kd-tree and normals built beforehand, for many alignments against one
// reference (every start of a retried match, every scan against one submap).
AlignmentResult alignPointSets(const IndexedReference& a, const PointSet& b, const common::Pose2& guess, const AlignerOptions& options);

Method parseMethod(const std::string& name);  // prior | icp | plicp | crf | crf+icp; throws invalid_argument
std::string methodName(Method method);

}  // namespace urbanslam::alignment
