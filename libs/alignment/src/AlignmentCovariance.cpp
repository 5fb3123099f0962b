#include "urbanslam/alignment/AlignmentCovariance.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <Eigen/Dense>

#include "urbanslam/alignment/NearestNeighbours.h"

namespace urbanslam::alignment {

using common::Pose2;

namespace {

struct Pair {
  int mov, ref;
  Eigen::Vector2d m;   // moving point in the reference frame
  Eigen::Vector2d dm;  // d m / d phi
};

// The pairs at `transform` within the association gate; with the reference's normals, not those
// whose sensors see the line from opposite sides (as point-to-line ICP pairs them).
std::vector<Pair> associations(const IndexedReference& reference, const std::vector<LineNormal>& normals, const PointSet& moving,
                               const Pose2& transform, const CovarianceOptions& options) {
  const NearestNeighbours& index = reference.index();
  const PointSet& ref = reference.points();
  const double tolerance = options.seen_side_tolerance_deg * M_PI / 180;
  const double gate = options.association_gate_m;
  const Rigid2 T = Rigid2::fromPose(transform);
  const double c = std::cos(transform.phi), s = std::sin(transform.phi);
  std::vector<Pair> out;
  for (size_t i = 0; i < moving.size(); ++i) {
    const Eigen::Vector2d& b = moving[i].p;
    const Eigen::Vector2d m = T * b;
    int j = 0;
    double d2 = 0;
    if (!index.nearestWithin(m, gate * gate, &j, &d2)) continue;
    if (!normals.empty() && !seenFromSameSide(normals[j], ref[j], T * moving[i].origin, tolerance)) continue;
    out.push_back({static_cast<int>(i), j, m, Eigen::Vector2d(-s * b.x() - c * b.y(), c * b.x() - s * b.y())});
  }
  return out;
}

Eigen::Matrix3d priorInformation(const CovarianceOptions& o) {
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  P(0, 0) = P(1, 1) = 1.0 / (o.max_std_m * o.max_std_m);
  P(2, 2) = 1.0 / (o.max_std_rad * o.max_std_rad);
  return P;
}

Eigen::Matrix3d largeCovariance(const CovarianceOptions& o) { return priorInformation(o).inverse(); }

Eigen::Matrix3d symmetric(const Eigen::Matrix3d& C) { return 0.5 * (C + C.transpose()); }

// Distance from reference point j to its nearest sweep neighbour: the spacing that limits how
// well a nearest-neighbour association can locate a point off any line.
double sweepSpacing(const PointSet& ref, int j) {
  double best = std::numeric_limits<double>::infinity();
  if (j > 0) best = std::min(best, (ref[j].p - ref[j - 1].p).norm());
  if (j + 1 < static_cast<int>(ref.size())) best = std::min(best, (ref[j].p - ref[j + 1].p).norm());
  return std::isfinite(best) ? best : 0.0;
}

}  // namespace

Eigen::Matrix3d lineVarianceCovariance(const IndexedReference& indexed, const PointSet& moving, const Pose2& transform,
                                       const CovarianceOptions& options) {
  const auto& normals = indexed.normals(options.normals);
  const auto pairs = associations(indexed, normals, moving, transform, options);
  if (pairs.size() < 3) return largeCovariance(options);
  const PointSet& reference = indexed.points();
  const Rigid2 T = Rigid2::fromPose(transform);
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  double chi2 = 0;
  int dof = 0;
  for (const auto& pr : pairs) {
    const ScanPoint& a = reference[pr.ref];
    const Eigen::Matrix2d C = a.cov + T.R * moving[pr.mov].cov * T.R.transpose();
    const Eigen::Vector2d r = pr.m - a.p;
    const LineNormal& ln = normals[pr.ref];
    if (ln.valid) {
      const Eigen::Vector3d J(ln.n.x(), ln.n.y(), ln.n.dot(pr.dm));
      const double var = ln.n.dot(C * ln.n) + ln.residual_var_m2;
      info += J * J.transpose() / var;
      chi2 += std::pow(ln.n.dot(r), 2) / var;
      dof += 1;
    } else {
      Eigen::Matrix<double, 2, 3> J;
      J << 1, 0, pr.dm.x(), 0, 1, pr.dm.y();
      const double sp = sweepSpacing(reference, pr.ref);
      const Eigen::Matrix2d Ci = (C + Eigen::Matrix2d::Identity() * (sp * sp / 12.0)).inverse();
      info += J.transpose() * Ci * J;
      chi2 += r.dot(Ci * r);
      dof += 2;
    }
  }
  Eigen::Matrix3d cov = (info + priorInformation(options)).inverse();
  if (options.scale_by_residuals && dof > 3) {
    const double red = chi2 / (dof - 3);
    if (red > 1.0) cov *= red;
  }
  return symmetric(cov);
}

Eigen::Matrix3d hessianCovariance(const IndexedReference& indexed, const PointSet& moving, const Pose2& transform,
                                  const CovarianceOptions& options) {
  const std::vector<LineNormal> none;
  const auto& normals = options.hessian_point_to_line ? indexed.normals(options.normals) : none;
  const auto pairs = associations(indexed, normals, moving, transform, options);
  if (pairs.size() < 3) return largeCovariance(options);
  const PointSet& reference = indexed.points();
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  double sse = 0;
  int n = 0;
  for (const auto& pr : pairs) {
    const Eigen::Vector2d r = pr.m - reference[pr.ref].p;
    if (!normals.empty() && normals[pr.ref].valid) {
      const Eigen::Vector2d& nn = normals[pr.ref].n;
      const Eigen::Vector3d J(nn.x(), nn.y(), nn.dot(pr.dm));
      A += J * J.transpose();
      sse += std::pow(nn.dot(r), 2);
      n += 1;
    } else {
      Eigen::Matrix<double, 2, 3> J;
      J << 1, 0, pr.dm.x(), 0, 1, pr.dm.y();
      A += J.transpose() * J;
      sse += r.squaredNorm();
      n += 2;
    }
  }
  if (n <= 3) return largeCovariance(options);
  // E = sum e^2 has Hessian 2A; cov = 2 s^2 (2A)^-1 with s^2 = E / (n - 3) (Bengtsson & Baerveldt).
  const double s2 = sse / (n - 3);
  const Eigen::Matrix3d info = A / std::max(s2, 1e-12) + priorInformation(options);
  return symmetric(info.inverse());
}

Eigen::Matrix3d samplingCovariance(const IndexedReference& indexed, const PointSet& moving, const Pose2& transform, const IcpOptions& icp,
                                   bool point_to_line, const CovarianceOptions& options) {
  const PointSet& reference = indexed.points();
  const NearestNeighbours& index = indexed.index();
  const std::vector<LineNormal> none;
  const auto& normals = point_to_line ? indexed.normals(icp.normals) : none;
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<Eigen::Vector3d> results;
  for (int k = 0; k < options.samples; ++k) {
    const Pose2 guess{transform.x + options.sample_sigma_m * nd(rng), transform.y + options.sample_sigma_m * nd(rng),
                      common::wrapToPi(transform.phi + options.sample_sigma_rad * nd(rng))};
    const auto r = icpWithIndex(reference, index, normals, moving, guess, icp);
    if (!r.converged) continue;
    results.emplace_back(r.transform.x, r.transform.y, transform.phi + common::wrapToPi(r.transform.phi - transform.phi));
  }
  if (results.size() < 3) return largeCovariance(options);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : results) mean += v;
  mean /= static_cast<double>(results.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& v : results) C += (v - mean) * (v - mean).transpose();
  C /= static_cast<double>(results.size() - 1);
  // A tiny floor keeps the result invertible when every sample lands on the same answer (which
  // is exactly why the thesis found this method far too confident).
  return symmetric(C + Eigen::Matrix3d::Identity() * 1e-12);
}

Eigen::Matrix3d alignmentCovariance(const PointSet& reference, const PointSet& moving, const Pose2& transform, const IcpOptions& icp,
                                    bool point_to_line, const CovarianceOptions& options) {
  return alignmentCovariance(IndexedReference(reference), moving, transform, icp, point_to_line, options);
}

Eigen::Matrix3d alignmentCovariance(const IndexedReference& reference, const PointSet& moving, const Pose2& transform,
                                    const IcpOptions& icp, bool point_to_line, const CovarianceOptions& options) {
  switch (options.method) {
    case CovarianceMethod::LineVariance:
      return lineVarianceCovariance(reference, moving, transform, options);
    case CovarianceMethod::Hessian:
      return hessianCovariance(reference, moving, transform, options);
    case CovarianceMethod::Sampling:
      return samplingCovariance(reference, moving, transform, icp, point_to_line, options);
  }
  return largeCovariance(options);
}

double translationConstraintRatio(const PointSet& reference, const PointSet& moving, const Pose2& transform,
                                  const CovarianceOptions& options) {
  return translationConstraintRatio(IndexedReference(reference), moving, transform, options);
}

double translationConstraintRatio(const IndexedReference& reference, const PointSet& moving, const Pose2& transform,
                                  const CovarianceOptions& options) {
  const auto& normals = reference.normals(options.normals);
  const auto pairs = associations(reference, normals, moving, transform, options);
  if (pairs.size() < 3) return 0.0;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (const auto& pr : pairs) {
    if (normals[pr.ref].valid) {
      const Eigen::Vector2d& nn = normals[pr.ref].n;
      const Eigen::Vector3d J(nn.x(), nn.y(), nn.dot(pr.dm));
      A += J * J.transpose();
    } else {
      Eigen::Matrix<double, 2, 3> J;
      J << 1, 0, pr.dm.x(), 0, 1, pr.dm.y();
      A += J.transpose() * J;
    }
  }
  Eigen::Matrix2d S = A.topLeftCorner<2, 2>();
  if (A(2, 2) > 1e-12) S -= A.topRightCorner<2, 1>() * A.bottomLeftCorner<1, 2>() / A(2, 2);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  const double lmax = es.eigenvalues()(1);
  return lmax > 0 ? std::max(0.0, es.eigenvalues()(0)) / lmax : 0.0;
}

CovarianceMethod parseCovarianceMethod(const std::string& name) {
  if (name == "line" || name == "line_variance") return CovarianceMethod::LineVariance;
  if (name == "hessian") return CovarianceMethod::Hessian;
  if (name == "sampling") return CovarianceMethod::Sampling;
  throw std::invalid_argument("unknown covariance method '" + name + "' (line, hessian, sampling)");
}

std::string covarianceMethodName(CovarianceMethod method) {
  switch (method) {
    case CovarianceMethod::LineVariance:
      return "line";
    case CovarianceMethod::Hessian:
      return "hessian";
    case CovarianceMethod::Sampling:
      return "sampling";
  }
  return "?";
}

}  // namespace urbanslam::alignment
