#pragma once
// Compounding operators of Smith, Self & Cheeseman (thesis appendix B) on Eigen 3-vectors
// (x, y, phi), with their analytic Jacobians.
//
// The filter keeps headings *unwrapped* (a continuous chart) so that the information vector
// eta = Lambda * mu stays consistent with the mean: wrapping a stored heading by 2*pi would
// silently change mu without changing eta. Only differences of headings are wrapped.
#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"

namespace urbanslam::esdf {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

inline Vec3 toVec(const common::Pose2& p) { return {p.x, p.y, p.phi}; }
inline common::Pose2 toPose(const Vec3& v) { return {v.x(), v.y(), common::wrapToPi(v.z())}; }

// a ⊕ b. The heading is a.phi + b.phi, not wrapped (see above).
Vec3 compose(const Vec3& a, const Vec3& b);
// J1⊕ = d(a⊕b)/da, J2⊕ = d(a⊕b)/db (appendix B.1).
void composeJacobians(const Vec3& a, const Vec3& b, Mat3* j1, Mat3* j2);

// ⊖a (heading -a.phi, not wrapped) and J⊖ = d(⊖a)/da (appendix B.2).
Vec3 inverse(const Vec3& a);
Mat3 inverseJacobian(const Vec3& a);

// ⊖a ⊕ b, heading difference wrapped to (-pi, pi]: the relative pose measurement model.
Vec3 between(const Vec3& a, const Vec3& b);
// d(⊖a⊕b)/da and d(⊖a⊕b)/db (composite relationship, appendix B.3: J1⊕ J⊖ and J2⊕).
void betweenJacobians(const Vec3& a, const Vec3& b, Mat3* ja, Mat3* jb);
// Covariance of ⊖a⊕b to first order, from the joint covariance of (a, b) (a's block first).
Mat3 betweenCovariance(const Vec3& a, const Vec3& b, const Eigen::Matrix<double, 6, 6>& joint);
// Standard deviation of a pose covariance's position part along its worst direction.
double largestPositionSigma(const Mat3& cov);
// `cov` with its diagonal raised to at least sigma_xy_m² (x, y) and sigma_phi_rad² (heading): a
// pose's uncertainty no smaller than what the estimate that produced it can be trusted to.
Mat3 withDiagonalFloors(const Mat3& cov, double sigma_xy_m, double sigma_phi_rad);

// Difference of two poses in the state chart: a - b with the heading difference wrapped.
inline Vec3 poseDifference(const Vec3& a, const Vec3& b) { return {a.x() - b.x(), a.y() - b.y(), common::wrapToPi(a.z() - b.z())}; }

// The error of a relative-pose edge in the g2o/MRPT convention, e = ⊖z ⊕ (⊖a ⊕ b), heading
// wrapped. Its chi-square e' Ω e is what `urbanslam graph` reports, so the filter uses this same
// error for its observation update: the estimate then converges to the optimum that the
// batch tools report, not to a slightly different one.
Vec3 relativePoseError(const Vec3& a, const Vec3& b, const Vec3& z);
// The same error with de/da and de/db (either may be null), in one evaluation.
Vec3 relativePoseError(const Vec3& a, const Vec3& b, const Vec3& z, Mat3* ja, Mat3* jb);
// de/da, de/db of relativePoseError.
void relativePoseErrorJacobians(const Vec3& a, const Vec3& b, const Vec3& z, Mat3* ja, Mat3* jb);

}  // namespace urbanslam::esdf
