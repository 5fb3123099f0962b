#include "urbanslam/alignment/BeamFreeSpace.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/common/RigidFit.h"

namespace urbanslam::alignment {

BeamFreeSpace::BeamFreeSpace(const PointSet& scan, double margin_m, double margin_fraction)
    : margin_m_(margin_m), margin_fraction_(margin_fraction) {
  if (scan.size() < 3) return;
  // The sensor's pose in the scan's frame: the rigid map from each point's polar coordinates to
  // its position (the point set may have been moved into the vehicle frame).
  std::vector<Eigen::Vector2d> polar, placed;
  double step = HUGE_VAL;
  for (size_t i = 0; i < scan.size(); ++i) {
    polar.emplace_back(scan[i].range_m * std::cos(scan[i].bearing_rad), scan[i].range_m * std::sin(scan[i].bearing_rad));
    placed.push_back(scan[i].p);
    if (i > 0 && scan[i].beam != scan[i - 1].beam) {
      // In double: beam indices read from a file may be anything, and an int difference overflow.
      const double d = std::abs(scan[i].bearing_rad - scan[i - 1].bearing_rad) /
                       std::abs(static_cast<double>(scan[i].beam) - static_cast<double>(scan[i - 1].beam));
      if (d > 1e-6) step = std::min(step, d);
    }
  }
  if (!std::isfinite(step) || !common::fitRigid2D(polar, placed, std::vector<double>(scan.size(), 1.0), &sensor_)) return;
  // Bins of the beam spacing (at least a quarter degree, so a bin usually holds a return).
  bin_rad_ = std::max(step, 0.25 * M_PI / 180);
  free_m_.assign(static_cast<size_t>(std::ceil(2 * M_PI / bin_rad_)), 0.0);
  for (const auto& sp : scan) {
    double& f = free_m_[binOf(sp.bearing_rad)];
    f = f > 0 ? std::min(f, sp.range_m) : sp.range_m;
  }
  valid_ = true;
}

size_t BeamFreeSpace::binOf(double bearing_rad) const {
  double from_zero = std::remainder(bearing_rad, 2 * M_PI);
  if (from_zero < 0) from_zero += 2 * M_PI;
  return static_cast<size_t>(from_zero / bin_rad_) % free_m_.size();
}

int BeamFreeSpace::conflicts(const std::vector<Eigen::Vector2d>& points, const common::Pose2& scan_pose) const {
  std::vector<char> state(points.size(), kUnseen);
  classify(points, scan_pose, state);
  return static_cast<int>(std::count(state.begin(), state.end(), kSeenThrough));
}

void BeamFreeSpace::classify(const std::vector<Eigen::Vector2d>& points, const common::Pose2& scan_pose, std::vector<char>& state) const {
  if (!valid_) return;
  const Rigid2 to_sensor = Rigid2::fromPose(common::inverse(common::compose(scan_pose, sensor_)));
  const size_t n = free_m_.size();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d q = to_sensor * points[i];
    const double r = q.norm();
    const size_t b = binOf(std::atan2(q.y(), q.x()));
    const double f = std::min({free_m_[b], free_m_[(b + 1) % n], free_m_[(b + n - 1) % n]});
    if (f <= 0) continue;
    const double g = std::max({free_m_[b], free_m_[(b + 1) % n], free_m_[(b + n - 1) % n]});
    const char s = r < f - margin_m_ - margin_fraction_ * f   ? kSeenThrough
                   : r > g + margin_m_ + margin_fraction_ * g ? kBehind
                                                              : kInView;
    state[i] = std::max(state[i], s);
  }
}

}  // namespace urbanslam::alignment
