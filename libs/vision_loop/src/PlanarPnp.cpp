#include "urbanslam/vision_loop/PlanarPnp.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace urbanslam::vision_loop {

bool planarProjection(const Eigen::Vector3d& p, const Eigen::Vector3d& x_a, Eigen::Vector2d* projection,
                      Eigen::Matrix<double, 2, 3>* d_pose, Eigen::Matrix<double, 2, 3>* d_point) {
  const double ct = std::cos(p(2)), st = std::sin(p(2));
  Eigen::Matrix3d r;
  r << ct, 0, st, 0, 1, 0, -st, 0, ct;
  const Eigen::Vector3d c(-p(1), 0, p(0));
  const Eigen::Vector3d d = x_a - c;
  const Eigen::Vector3d xb = r * d;
  if (!(xb.z() > 1e-9)) return false;
  const double iz = 1.0 / xb.z();
  *projection = Eigen::Vector2d(xb.x() * iz, xb.y() * iz);
  if (!d_pose && !d_point) return true;
  Eigen::Matrix<double, 2, 3> dn;  // d projection / d X_b
  dn << iz, 0, -xb.x() * iz * iz, 0, iz, -xb.y() * iz * iz;
  if (d_point) *d_point = dn * r;
  if (d_pose) {
    Eigen::Matrix3d dr;
    dr << -st, 0, ct, 0, 0, 0, -ct, 0, -st;
    // X_b = R (x_a - c): d/df = -R e_z, d/dl = R e_x (c = (-l, 0, f)), d/dθ = R' (x_a - c).
    d_pose->col(0) = dn * (-r.col(2));
    d_pose->col(1) = dn * r.col(0);
    d_pose->col(2) = dn * (dr * d);
  }
  return true;
}

PlanarPnpFit fitPlanarPnp(const std::vector<PlanarPnpPoint>& points, const Eigen::Vector3d& start, double pixel_sigma, int max_iterations) {
  PlanarPnpFit fit;
  fit.pose = start;
  const size_t n = points.size();
  if (n < 3) return fit;
  const Eigen::Matrix2d noise = pixel_sigma * pixel_sigma * Eigen::Matrix2d::Identity();
  // Whitened residuals and Jacobians at a pose; false when a point falls behind camera b.
  struct Linear {
    std::vector<Eigen::Vector2d> e;
    std::vector<Eigen::Matrix<double, 2, 3>> j;
  };
  const auto linearise = [&](const Eigen::Vector3d& p, Linear* out) {
    out->e.resize(n);
    out->j.resize(n);
    for (size_t i = 0; i < n; ++i) {
      Eigen::Vector2d proj;
      Eigen::Matrix<double, 2, 3> jp, jx;
      if (!planarProjection(p, points[i].x_a, &proj, &jp, &jx)) return false;
      // The point's covariance seen in b's image, plus the pixel noise: whiten by its inverse root.
      const Eigen::Matrix2d s = noise + jx * points[i].cov_a * jx.transpose();
      const Eigen::Matrix2d l = Eigen::LLT<Eigen::Matrix2d>(s).matrixL();
      const Eigen::Matrix2d li = l.inverse();
      out->e[i] = li * (proj - points[i].seen_b);
      out->j[i] = li * jp;
    }
    return true;
  };
  // Cauchy weights, the scale from the residuals' median (at least the noise model's own).
  const auto weights = [&](const Linear& lin) {
    std::vector<double> norm(n);
    for (size_t i = 0; i < n; ++i) norm[i] = lin.e[i].norm();
    std::vector<double> sorted = norm;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(n / 2), sorted.end());
    const double scale = 2.3849 * std::max(1.0, sorted[n / 2] / 1.1774);  // 1.1774: median norm of a unit 2D Gaussian
    std::vector<double> w(n);
    for (size_t i = 0; i < n; ++i) w[i] = 1.0 / (1.0 + (norm[i] / scale) * (norm[i] / scale));
    return w;
  };
  const auto cost = [&](const Linear& lin, const std::vector<double>& w) {
    double c = 0;
    for (size_t i = 0; i < n; ++i) c += w[i] * lin.e[i].squaredNorm();
    return c;
  };
  Linear lin;
  if (!linearise(fit.pose, &lin)) return fit;
  std::vector<double> w = weights(lin);
  double lambda = 1e-3;
  int it = 0;
  for (; it < max_iterations; ++it) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < n; ++i) {
      h += w[i] * lin.j[i].transpose() * lin.j[i];
      g += w[i] * lin.j[i].transpose() * lin.e[i];
    }
    const double before = cost(lin, w);
    bool improved = false;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Eigen::Matrix3d damped = h;
      damped.diagonal() *= 1.0 + lambda;
      step = -damped.ldlt().solve(g);
      Linear trial;
      if (step.allFinite() && linearise(fit.pose + step, &trial) && cost(trial, w) < before) {
        fit.pose += step;
        lin = std::move(trial);
        lambda = std::max(1e-9, lambda * 0.3);
        improved = true;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
    w = weights(lin);
    if (std::abs(step(0)) < 1e-9 && std::abs(step(1)) < 1e-9 && std::abs(step(2)) < 1e-10) break;
  }
  fit.iterations = it;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  double weighted = 0, total = 0;
  for (size_t i = 0; i < n; ++i) {
    h += w[i] * lin.j[i].transpose() * lin.j[i];
    weighted += w[i] * lin.e[i].squaredNorm();
    total += w[i];
  }
  // The whitened residuals' variance: 1 when the noise model holds; larger, the covariance grows.
  const double dof = std::max(1.0, 2.0 * total - 3.0);
  const double variance = weighted / dof;
  fit.rms_whitened = std::sqrt(variance);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(h);
  if (!lu.isInvertible()) return fit;
  fit.cov = std::max(1.0, variance) * lu.inverse();
  fit.converged = fit.cov.allFinite();
  return fit;
}

}  // namespace urbanslam::vision_loop
