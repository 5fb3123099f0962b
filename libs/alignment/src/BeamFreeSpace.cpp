#include "urbanslam/alignment/BeamFreeSpace.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/common/RigidFit.h"

namespace urbanslam::alignment {

namespace {

// atan2 to about 1e-5 rad (Abramowitz & Stegun 4.4.49 on the octant: 1.2e-5 at most), a
// fortieth of the narrowest bin: the bearing only picks a bin, whose neighbours are consulted
// too, and the library's exact atan2 was the largest cost of matching against a map's scans.
double fastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  if (ax == 0 && ay == 0) return 0.0;
  const bool steep = ay > ax;
  const double z = steep ? ax / ay : ay / ax;  // in [0, 1]
  const double z2 = z * z;
  double a = z * (0.9998660 + z2 * (-0.3302995 + z2 * (0.1801410 + z2 * (-0.0851330 + z2 * 0.0208351))));
  if (steep) a = M_PI_2 - a;
  if (x < 0) a = M_PI - a;
  return y < 0 ? -a : a;
}

}  // namespace

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
  for (double f : free_m_) reach_m_ = std::max(reach_m_, f + margin_m_ + margin_fraction_ * f);
  valid_ = true;
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
    // Points this scan cannot raise are skipped before the bearing (matched against a map's
    // many keyframe scans, most points lie beyond most scans' reach, or were seen through).
    if (state[i] == kSeenThrough) continue;
    const Eigen::Vector2d q = to_sensor * points[i];
    const double r = q.norm();
    if (r > reach_m_ && state[i] >= kBehind) continue;
    const size_t b = binOf(fastAtan2(q.y(), q.x()));
    const double here = free_m_[b], next = free_m_[b + 1 == n ? 0 : b + 1], before = free_m_[b == 0 ? n - 1 : b - 1];
    const double f = std::min({here, next, before});
    if (f <= 0) continue;
    const double g = std::max({here, next, before});
    const char s = r < f - margin_m_ - margin_fraction_ * f   ? kSeenThrough
                   : r > g + margin_m_ + margin_fraction_ * g ? kBehind
                                                              : kInView;
    state[i] = std::max(state[i], s);
  }
}

}  // namespace urbanslam::alignment
