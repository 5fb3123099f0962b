#include "urbanslam/esdf/PoseChainSmoother.h"

#include <Eigen/Cholesky>
#include <stdexcept>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::esdf {

namespace {

// The Kalman update by a fix of the pose itself (H = I); the heading stays on the branch of the
// estimate: only the difference is wrapped.
void update(Vec3& x, Mat3& p, const Vec3& z, const Mat3& r) {
  const Mat3 k = (p + r).ldlt().solve(p).transpose();  // P (P + R)⁻¹, P and R symmetric
  x += k * poseDifference(z, x);
  p = (Mat3::Identity() - k) * p;
  p = 0.5 * (p + p.transpose());
}

// The prediction of the next pose by `motion` from the previous one (x, p), linearised about
// `at` (x itself, for the filter): x⁻ = at ⊕ u + F (x − at), P⁻ = F P F' + G Q G' (F, G: the
// composition's Jacobians at `at`, thesis appendix B). Returns F.
Mat3 predict(const Vec3& at, Vec3& x, Mat3& p, const Vec3& motion, const Mat3& motion_cov) {
  Mat3 f, g;
  composeJacobians(at, motion, &f, &g);
  x = compose(at, motion) + f * poseDifference(x, at);
  p = f * p * f.transpose() + g * motion_cov * g.transpose();
  return f;
}

}  // namespace

size_t PoseChainSmoother::addPose(const common::Pose2& motion, const Eigen::Matrix3d& cov) {
  Node n;
  n.motion = toVec(motion);
  n.motion_cov = 0.5 * (cov + cov.transpose());
  if (hasFix()) predict(Vec3(x_), x_, p_, n.motion, n.motion_cov);
  nodes_.push_back(std::move(n));
  return nodes_.size() - 1;
}

void PoseChainSmoother::addFix(const common::Pose2& pose, const Eigen::Matrix3d& cov) {
  if (nodes_.empty()) throw std::logic_error("PoseChainSmoother::addFix before addPose");
  Fix fix{toVec(pose), 0.5 * (cov + cov.transpose())};
  if (!hasFix()) {
    // The first fix starts the filter: before it the chain floats.
    first_fixed_ = nodes_.size() - 1;
    x_ = fix.pose;
    p_ = fix.cov;
  } else {
    update(x_, p_, fix.pose, fix.cov);
  }
  nodes_.back().fixes.push_back(std::move(fix));
}

common::Pose2 PoseChainSmoother::filtered() const {
  if (!hasFix()) throw std::logic_error("PoseChainSmoother::filtered without a fix");
  return toPose(x_);
}

std::vector<Vec3> PoseChainSmoother::pass(const std::vector<Vec3>& about) const {
  const size_t n = nodes_.size() - first_fixed_;
  // Forward: the filter, its prediction linearised about `about` when given (as Gauss-Newton
  // takes it), else about the filter's own estimate.
  std::vector<Vec3> x(n), x_pred(n);
  std::vector<Mat3> p(n), p_pred(n), f(n);
  for (size_t k = 0; k < n; ++k) {
    const Node& node = nodes_[first_fixed_ + k];
    size_t first_update = 0;
    if (k == 0) {
      x[0] = node.fixes[0].pose;
      p[0] = node.fixes[0].cov;
      first_update = 1;
    } else {
      x_pred[k] = x[k - 1];
      p_pred[k] = p[k - 1];
      f[k] = predict(about.empty() ? x[k - 1] : about[k - 1], x_pred[k], p_pred[k], node.motion, node.motion_cov);
      x[k] = x_pred[k];
      p[k] = p_pred[k];
    }
    for (size_t j = first_update; j < node.fixes.size(); ++j) update(x[k], p[k], node.fixes[j].pose, node.fixes[j].cov);
  }
  // Backward: x̂ᵢ = xᵢ + Cᵢ (x̂ᵢ₊₁ − x⁻ᵢ₊₁), Cᵢ = Pᵢ Fᵢ₊₁' (P⁻ᵢ₊₁)⁻¹.
  for (size_t k = n - 1; k-- > 0;) {
    const Mat3 c = p_pred[k + 1].ldlt().solve(f[k + 1] * p[k]).transpose();
    x[k] += c * poseDifference(x[k + 1], x_pred[k + 1]);
  }
  return x;
}

std::vector<common::Pose2> PoseChainSmoother::smooth(int max_iterations, double tolerance) const {
  if (!hasFix()) return {};
  std::vector<Vec3> xs;
  for (int it = 0; it < std::max(1, max_iterations); ++it) {
    std::vector<Vec3> next = pass(xs);
    double moved = 0;
    if (!xs.empty())
      for (size_t k = 0; k < next.size(); ++k) moved = std::max(moved, poseDifference(next[k], xs[k]).cwiseAbs().maxCoeff());
    const bool first = xs.empty();
    xs = std::move(next);
    if (!first && moved <= tolerance) break;
  }
  // Before the first fix: back along the chain from it, xᵢ = xᵢ₊₁ ⊕ ⊖uᵢ₊₁.
  std::vector<common::Pose2> out(nodes_.size());
  for (size_t k = 0; k < xs.size(); ++k) out[first_fixed_ + k] = toPose(xs[k]);
  Vec3 back = xs.front();
  for (size_t i = first_fixed_; i-- > 0;) {
    back = compose(back, inverse(nodes_[i + 1].motion));
    out[i] = toPose(back);
  }
  return out;
}

}  // namespace urbanslam::esdf
