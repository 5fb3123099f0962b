#pragma once
// A 2D pose (x, y, heading) and the compounding operators of Smith, Self & Cheeseman
// (thesis appendix B): a ⊕ b, ⊖a and ⊖a ⊕ b. Kept dependency-free so every module can use it;
// the Jacobians live with the estimator (libs/esdf) that needs them.
#include <cmath>

namespace urbanslam::common {

// Wraps an angle to (-pi, pi].
inline double wrapToPi(double a) {
  if (a > -M_PI && a <= M_PI) return a;  // the common case, without the costly fmod
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a <= 0.0) a += 2.0 * M_PI;
  return a - M_PI;
}

struct Pose2 {
  double x = 0, y = 0, phi = 0;
};

// a ⊕ b: b expressed in a's frame, returned in the world frame.
inline Pose2 compose(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.phi), s = std::sin(a.phi);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, wrapToPi(a.phi + b.phi)};
}

// ⊖a
inline Pose2 inverse(const Pose2& a) {
  const double c = std::cos(a.phi), s = std::sin(a.phi);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, wrapToPi(-a.phi)};
}

// ⊖a ⊕ b: the pose of b seen from a (the relative-pose measurement z of the filter).
inline Pose2 between(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.phi), s = std::sin(a.phi);
  const double dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, wrapToPi(b.phi - a.phi)};
}

// Pose at fraction f in [0,1] from a to b (heading along the shortest arc).
inline Pose2 interpolate(const Pose2& a, const Pose2& b, double f) {
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), wrapToPi(a.phi + f * wrapToPi(b.phi - a.phi))};
}

}  // namespace urbanslam::common
