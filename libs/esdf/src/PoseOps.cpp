#include "urbanslam/esdf/PoseOps.h"

#include <cmath>

namespace urbanslam::esdf {

Vec3 compose(const Vec3& a, const Vec3& b) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  return {a.x() + c * b.x() - s * b.y(), a.y() + s * b.x() + c * b.y(), a.z() + b.z()};
}

void composeJacobians(const Vec3& a, const Vec3& b, Mat3* j1, Mat3* j2) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  if (j1) {
    // Rows: x, y, phi of the result; d/dphi_a rotates b by 90 degrees.
    *j1 << 1, 0, -s * b.x() - c * b.y(),
           0, 1, c * b.x() - s * b.y(),
           0, 0, 1;
  }
  if (j2) {
    *j2 << c, -s, 0,
           s, c, 0,
           0, 0, 1;
  }
}

Vec3 inverse(const Vec3& a) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  return {-c * a.x() - s * a.y(), s * a.x() - c * a.y(), -a.z()};
}

Mat3 inverseJacobian(const Vec3& a) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  Mat3 j;
  j << -c, -s, s * a.x() - c * a.y(),
        s, -c, c * a.x() + s * a.y(),
        0, 0, -1;
  return j;
}

Vec3 between(const Vec3& a, const Vec3& b) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  return {c * dx + s * dy, -s * dx + c * dy, common::wrapToPi(b.z() - a.z())};
}

void betweenJacobians(const Vec3& a, const Vec3& b, Mat3* ja, Mat3* jb) {
  // Written out rather than chained through J1⊕ J⊖: same values, one trig evaluation.
  const double c = std::cos(a.z()), s = std::sin(a.z());
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  if (ja) {
    *ja << -c, -s, -s * dx + c * dy,
            s, -c, -c * dx - s * dy,
            0, 0, -1;
  }
  if (jb) {
    *jb << c, s, 0,
          -s, c, 0,
           0, 0, 1;
  }
}

Vec3 relativePoseError(const Vec3& a, const Vec3& b, const Vec3& z) {
  Vec3 e = compose(inverse(z), between(a, b));
  e.z() = common::wrapToPi(e.z());
  return e;
}

void relativePoseErrorJacobians(const Vec3& a, const Vec3& b, const Vec3& z, Mat3* ja, Mat3* jb) {
  // e = ⊖z ⊕ h(a, b): chain rule through J2⊕ evaluated at (⊖z, h).
  Mat3 jh;
  composeJacobians(inverse(z), between(a, b), nullptr, &jh);
  Mat3 ha, hb;
  betweenJacobians(a, b, &ha, &hb);
  if (ja) *ja = jh * ha;
  if (jb) *jb = jh * hb;
}

}  // namespace urbanslam::esdf
