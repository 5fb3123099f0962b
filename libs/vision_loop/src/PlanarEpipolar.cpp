#include "urbanslam/vision_loop/PlanarEpipolar.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace urbanslam::vision_loop {

namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

Eigen::Matrix3d rotationY(double a) {
  Eigen::Matrix3d r;
  r << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return r;
}

// E = [t]x R with t = -R c equals -R [c]x ([R c]x = R [c]x R'); and its derivatives.
struct Essential {
  Eigen::Matrix3d e, d_bearing, d_heading;
  Essential(double bearing, double heading) {
    const Eigen::Vector3d c(-std::sin(bearing), 0, std::cos(bearing));
    const Eigen::Vector3d dc(-std::cos(bearing), 0, -std::sin(bearing));
    const Eigen::Matrix3d r = rotationY(heading);
    Eigen::Matrix3d dr;
    dr << -std::sin(heading), 0, std::cos(heading), 0, 0, 0, -std::cos(heading), 0, -std::sin(heading);
    e = -r * skew(c);
    d_bearing = -r * skew(dc);
    d_heading = -dr * skew(c);
  }
};

Eigen::Vector3d homogeneous(const Eigen::Vector2d& p) { return {p.x(), p.y(), 1.0}; }

}  // namespace

Eigen::Matrix3d planarEssential(double bearing_rad, double heading_rad) { return Essential(bearing_rad, heading_rad).e; }

double sampsonResidual(const Eigen::Matrix3d& e, const Eigen::Vector2d& xa, const Eigen::Vector2d& xb) {
  const Eigen::Vector3d a = homogeneous(xa), b = homogeneous(xb);
  const Eigen::Vector3d ea = e * a, eb = e.transpose() * b;
  const double d = ea.x() * ea.x() + ea.y() * ea.y() + eb.x() * eb.x() + eb.y() * eb.y();
  return d > 0 ? b.dot(ea) / std::sqrt(d) : 0.0;
}

Eigen::MatrixX2d sampsonJacobian(double bearing_rad, double heading_rad, const std::vector<Eigen::Vector2d>& a_points,
                                 const std::vector<Eigen::Vector2d>& b_points) {
  const Essential m(bearing_rad, heading_rad);
  Eigen::MatrixX2d j(static_cast<Eigen::Index>(a_points.size()), 2);
  for (size_t i = 0; i < a_points.size(); ++i) {
    const Eigen::Vector3d a = homogeneous(a_points[i]), b = homogeneous(b_points[i]);
    const Eigen::Vector3d ea = m.e * a, eb = m.e.transpose() * b;
    const double num = b.dot(ea);
    const double d = ea.x() * ea.x() + ea.y() * ea.y() + eb.x() * eb.x() + eb.y() * eb.y();
    if (!(d > 0)) {
      j.row(static_cast<Eigen::Index>(i)).setZero();
      continue;
    }
    const double sd = std::sqrt(d);
    int col = 0;
    for (const Eigen::Matrix3d* de : {&m.d_bearing, &m.d_heading}) {
      const Eigen::Vector3d dea = *de * a, deb = de->transpose() * b;
      const double dnum = b.dot(dea);
      const double dd = 2 * (ea.x() * dea.x() + ea.y() * dea.y() + eb.x() * deb.x() + eb.y() * deb.y());
      j(static_cast<Eigen::Index>(i), col++) = dnum / sd - 0.5 * num * dd / (d * sd);
    }
  }
  return j;
}

PlanarEpipolarFit fitPlanarEpipolar(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double bearing_rad,
                                    double heading_rad, double min_sigma, int max_iterations) {
  PlanarEpipolarFit fit;
  fit.bearing_rad = bearing_rad;
  fit.heading_rad = heading_rad;
  const size_t n = a.size();
  if (n < 3 || b.size() != n) return fit;
  const auto residuals = [&](double bearing, double heading) {
    const Eigen::Matrix3d e = planarEssential(bearing, heading);
    Eigen::VectorXd r(static_cast<Eigen::Index>(n));
    for (size_t i = 0; i < n; ++i) r(static_cast<Eigen::Index>(i)) = sampsonResidual(e, a[i], b[i]);
    return r;
  };
  // Iteratively reweighted: RANSAC's inliers still hold mismatches within its threshold, whose
  // pull a Cauchy weight (scale from the residuals' median absolute deviation) removes.
  Eigen::VectorXd w = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(n));
  double sigma = 0;
  const auto robustScale = [&](const Eigen::VectorXd& r) {
    std::vector<double> v(r.data(), r.data() + r.size());
    for (double& x : v) x = std::abs(x);
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return std::max(1.4826 * v[v.size() / 2], min_sigma);
  };
  Eigen::MatrixX2d j;
  Eigen::VectorXd r;
  for (int round = 0; round < 4; ++round) {
    // Levenberg-Marquardt on the weighted residuals: near forward or backward motion (the
    // epipole inside the image) the bearing is weakly determined and the cost far from
    // quadratic, where plain Gauss-Newton steps overshoot.
    r = residuals(fit.bearing_rad, fit.heading_rad);
    double cost = (w.array() * r.array().square()).sum();
    j = sampsonJacobian(fit.bearing_rad, fit.heading_rad, a, b);
    double lambda = 1e-3;
    for (int it = 0; it < max_iterations; ++it, ++fit.iterations) {
      const Eigen::Matrix2d h = j.transpose() * w.asDiagonal() * j;
      const Eigen::Vector2d g = j.transpose() * (w.array() * r.array()).matrix();
      bool improved = false, settled = false;
      for (int k = 0; k < 20 && !improved; ++k) {
        Eigen::Matrix2d damped = h;
        damped.diagonal() *= 1.0 + lambda;
        const Eigen::Vector2d step = damped.ldlt().solve(-g);
        if (!step.allFinite()) return fit;
        const Eigen::VectorXd r_new = residuals(fit.bearing_rad + step(0), fit.heading_rad + step(1));
        const double cost_new = (w.array() * r_new.array().square()).sum();
        if (cost_new < cost) {
          fit.bearing_rad += step(0);
          fit.heading_rad += step(1);
          settled = step.norm() < 1e-10 || cost - cost_new <= 1e-14 * std::max(cost_new, 1e-300);
          r = r_new;
          cost = cost_new;
          lambda = std::max(1e-9, lambda * 0.3);
          improved = true;
          j = sampsonJacobian(fit.bearing_rad, fit.heading_rad, a, b);
        } else {
          lambda *= 10;
        }
      }
      if (!improved || settled) break;  // at the minimum
    }
    sigma = robustScale(r);
    const double c = 2.3849 * sigma;  // Cauchy: 95 % efficiency under Gaussian noise
    w = (1.0 + (r.array() / c).square()).inverse().matrix();
  }
  fit.bearing_rad = std::atan2(std::sin(fit.bearing_rad), std::cos(fit.bearing_rad));
  fit.heading_rad = std::atan2(std::sin(fit.heading_rad), std::cos(fit.heading_rad));
  fit.rms_residual = std::sqrt(r.squaredNorm() / static_cast<double>(n));
  // First-order covariance of the weighted fit: the noise's robust variance times (J'WJ)^-1.
  const Eigen::Matrix2d h = j.transpose() * w.asDiagonal() * j;
  Eigen::FullPivLU<Eigen::Matrix2d> lu(h);
  if (!lu.isInvertible()) return fit;
  fit.cov = sigma * sigma * lu.inverse();
  fit.converged = fit.cov.allFinite();
  return fit;
}

std::optional<RayMeeting> meetRays(const Eigen::Vector2d& xa, const Eigen::Vector2d& xb, double bearing_rad, double heading_rad,
                                   double baseline) {
  // X_a = λ_a d_a = c + λ_b R' d_b (X_b = R (X_a - c)): two unknowns, three equations.
  const Eigen::Vector3d c(-baseline * std::sin(bearing_rad), 0, baseline * std::cos(bearing_rad));
  const Eigen::Vector3d da = homogeneous(xa), db = rotationY(heading_rad).transpose() * homogeneous(xb);
  Eigen::Matrix<double, 3, 2> m;
  m.col(0) = da;
  m.col(1) = -db;
  const Eigen::Matrix2d normal = m.transpose() * m;
  const double det = normal.determinant();
  if (!(det > 1e-12 * normal.trace() * normal.trace())) return std::nullopt;
  const Eigen::Vector2d lambda = normal.inverse() * (m.transpose() * c);
  RayMeeting r;
  r.depth_a = lambda(0);  // z of λ_a d_a: d_a's z is 1
  r.along_b = lambda(1);
  r.midpoint = 0.5 * (lambda(0) * da + c + lambda(1) * db);
  r.parallax_rad = std::acos(std::clamp(da.normalized().dot(db.normalized()), -1.0, 1.0));
  return r;
}

double sceneDepthPerBaseline(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double bearing_rad,
                             double heading_rad) {
  const size_t n = std::min(a.size(), b.size());
  if (n == 0) return std::numeric_limits<double>::infinity();
  std::vector<double> depth(n, std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < n; ++i) {
    // Parallel rays (no parallax) meet nowhere: the scene point is as far as the baseline allows.
    const auto meeting = meetRays(a[i], b[i], bearing_rad, heading_rad, 1.0);
    if (meeting && meeting->depth_a > 0 && meeting->along_b > 0) depth[i] = meeting->depth_a;
  }
  std::nth_element(depth.begin(), depth.begin() + static_cast<long>(n / 4), depth.end());
  return depth[n / 4];
}

}  // namespace urbanslam::vision_loop
