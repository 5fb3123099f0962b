#pragma once
// Covariance of a scan alignment (thesis §3.3.3). It goes straight into the filter, so an
// overconfident value corrupts the map. Three selectable methods:
//
//  * LineVariance (the thesis's choice): the point covariances of both scans (eqs. 3.3-3.5) are
//    combined through the nearest-neighbour associations at the final transform. Each pair gives
//    the covariance of its point-to-point offset, C = C_ref + R C_mov R^T; where the reference
//    point lies on a line (LineNormals.h) only the offset across the line is information (a
//    point may slide along a wall: this is what makes a corridor uncertain along its axis), so
//    the pair contributes J^T J / (n^T C n + line roughness); elsewhere J^T C^-1 J. The pair
//    informations are summed and inverted. Optionally the result is inflated by the reduced
//    chi-square of the residuals when they are larger than the noise model predicts.
//  * Hessian (Bengtsson & Baerveldt 2003; cf. Censi 2007): cov = s^2 (sum J^T J)^-1 with s^2 the
//    residual variance, J the Jacobian of the minimised error. Ignores the sensor noise model.
//  * Sampling (cf. thesis ref. [39]): ICP from random initial guesses around the estimate; the
//    covariance of the results.
//
// All three add a weak prior (max_std_*) so that a direction the scans leave free comes out
// large and finite instead of singular.
#include <string>

#include <Eigen/Core>

#include "urbanslam/alignment/Icp.h"
#include "urbanslam/alignment/IndexedReference.h"
#include "urbanslam/alignment/LineNormals.h"
#include "urbanslam/alignment/PointSet.h"

namespace urbanslam::alignment {

enum class CovarianceMethod { LineVariance, Hessian, Sampling };

struct CovarianceOptions {
  CovarianceMethod method = CovarianceMethod::LineVariance;
  double association_gate_m = 0.3;  // pairs farther apart at the final transform are ignored
  LineNormalOptions normals;
  // With normals, no pair whose sensors see its line from opposite sides, each more steeply than
  // this, as point-to-line ICP pairs them (IcpOptions); < 0: every pair.
  double seen_side_tolerance_deg = 10;
  bool scale_by_residuals = true;  // line variance: inflate by chi^2/dof when it exceeds 1
  double max_std_m = 100.0;        // weak prior bounding free directions
  double max_std_rad = 3.14159;
  bool hessian_point_to_line = false;  // Hessian of the point-to-line error instead of point-to-point
  int samples = 30;                    // sampling method
  double sample_sigma_m = 0.3;
  double sample_sigma_rad = 0.1;
  unsigned seed = 1;
};

// Covariance of `transform` (the pose of `moving` in `reference`'s frame), order (x, y, phi).
Eigen::Matrix3d lineVarianceCovariance(const IndexedReference& reference, const PointSet& moving, const common::Pose2& transform,
                                       const CovarianceOptions& options);
Eigen::Matrix3d hessianCovariance(const IndexedReference& reference, const PointSet& moving, const common::Pose2& transform,
                                  const CovarianceOptions& options);
Eigen::Matrix3d samplingCovariance(const IndexedReference& reference, const PointSet& moving, const common::Pose2& transform,
                                   const IcpOptions& icp, bool point_to_line, const CovarianceOptions& options);

// Dispatch on options.method (the ICP options are used by Sampling only).
Eigen::Matrix3d alignmentCovariance(const IndexedReference& reference, const PointSet& moving, const common::Pose2& transform,
                                    const IcpOptions& icp, bool point_to_line, const CovarianceOptions& options);
Eigen::Matrix3d alignmentCovariance(const PointSet& reference, const PointSet& moving, const common::Pose2& transform,
                                    const IcpOptions& icp, bool point_to_line, const CovarianceOptions& options);

// How well the geometry constrains the translation: ratio of the smallest to the largest
// eigenvalue of the translational point-to-line information (with the rotation marginalised).
// Near 0 for a corridor (free along its axis), near 1 for a room corner. 0 without associations.
double translationConstraintRatio(const IndexedReference& reference, const PointSet& moving, const common::Pose2& transform,
                                  const CovarianceOptions& options);
double translationConstraintRatio(const PointSet& reference, const PointSet& moving, const common::Pose2& transform,
                                  const CovarianceOptions& options);

CovarianceMethod parseCovarianceMethod(const std::string& name);  // line|hessian|sampling
std::string covarianceMethodName(CovarianceMethod method);

}  // namespace urbanslam::alignment
