#include "urbanslam/common/RigidFit.h"

#include <cmath>

namespace urbanslam::common {

bool fitRigid2D(const std::vector<Eigen::Vector2d>& src, const std::vector<Eigen::Vector2d>& dst, const std::vector<double>& weights,
                Pose2* transform) {
  if (src.size() < 2 || src.size() != dst.size() || (!weights.empty() && weights.size() != src.size())) return false;
  const auto w = [&](size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  double W = 0;
  Eigen::Vector2d ms = Eigen::Vector2d::Zero(), md = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    W += w(i);
    ms += w(i) * src[i];
    md += w(i) * dst[i];
  }
  if (!(W > 0)) return false;
  ms /= W;
  md /= W;
  double sxx = 0, sxy = 0, syx = 0, syy = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Eigen::Vector2d a = src[i] - ms, b = dst[i] - md;
    sxx += w(i) * a.x() * b.x();
    sxy += w(i) * a.x() * b.y();
    syx += w(i) * a.y() * b.x();
    syy += w(i) * a.y() * b.y();
  }
  // The rotation maximising sum w (R a) . b has tan(phi) = (sxy - syx) / (sxx + syy).
  const double phi = std::atan2(sxy - syx, sxx + syy);
  const double c = std::cos(phi), s = std::sin(phi);
  transform->phi = phi;
  transform->x = md.x() - (c * ms.x() - s * ms.y());
  transform->y = md.y() - (s * ms.x() + c * ms.y());
  return std::isfinite(transform->x) && std::isfinite(transform->y) && std::isfinite(phi);
}

}  // namespace urbanslam::common
