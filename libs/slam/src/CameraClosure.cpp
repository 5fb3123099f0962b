#include "urbanslam/slam/CameraClosure.h"

#include <Eigen/LU>
#include <cmath>

#include "urbanslam/esdf/PoseOps.h"

namespace urbanslam::slam {

vision_loop::PinholeCamera pinholeFor(const io::CameraCalibration& c, int image_width_px, int features_width_px) {
  const double s = image_width_px > 0 && features_width_px > 0 ? static_cast<double>(features_width_px) / image_width_px : 1.0;
  vision_loop::PinholeCamera k;
  k.fx = c.fx_px * s;
  k.fy = c.fy_px * s;
  // Pixel centres at integers: scaling maps pixel edges, so the centre moves by half a pixel.
  k.cx = (c.cx_px + 0.5) * s - 0.5;
  k.cy = (c.cy_px + 0.5) * s - 0.5;
  return k;
}

esdf::RelativeFactor cameraFactor(const CameraMeasurement& m, const esdf::Vec3& x_i, const esdf::Vec3& x_j) {
  const esdf::Vec3 mount = esdf::toVec(m.mount);
  esdf::RelativeFactor fc;  // in the cameras' frame
  if (m.metric.valid) {
    fc.z = esdf::toVec(m.metric.pose);
    fc.omega = m.metric.cov.inverse();
  } else {
    const esdf::Vec3 c = esdf::between(esdf::compose(x_i, mount), esdf::compose(x_j, mount));
    // Where the estimate puts camera j from camera i; at least a metre, so that a revisit the
    // estimate puts on the same spot does not turn the bearing into an unbounded lateral stiffness.
    const double range = std::max(1.0, std::hypot(c.x(), c.y()));
    esdf::BearingHeading bh;
    bh.bearing_rad = m.relative.bearing_rad;
    bh.heading_rad = m.relative.heading_rad;
    bh.information = m.relative.cov.inverse();
    fc = esdf::relativeFactor(bh, range, esdf::weakRangeSigma(range));
  }
  // m ⊕ e ⊕ ⊖m = Adj(m) e to first order: [R(φm) (y_m, -x_m)'; 0 1].
  const double cs = std::cos(mount.z()), sn = std::sin(mount.z());
  esdf::Mat3 adj;
  adj << cs, -sn, mount.y(),  //
      sn, cs, -mount.x(),     //
      0, 0, 1;
  const esdf::Mat3 inv = adj.inverse();
  esdf::RelativeFactor f;
  f.z = esdf::compose(esdf::compose(mount, fc.z), esdf::inverse(mount));
  f.omega = inv.transpose() * fc.omega * inv;
  f.omega = 0.5 * (f.omega + f.omega.transpose());
  return f;
}

double nearestSceneDepth(const CameraMeasurement& m, const esdf::Vec3& x_i, const esdf::Vec3& x_j, const Eigen::Matrix3d& relative_cov) {
  const esdf::Vec3 mount = esdf::toVec(m.mount);
  const esdf::Vec3 c = esdf::between(esdf::compose(x_i, mount), esdf::compose(x_j, mount));
  // The cameras' relative position spreads as the vehicles' does (the mount is rigid; the
  // heading's share, the mount's lever arm times its sigma, is centimetres against metres).
  const double baseline = std::hypot(c.x(), c.y()) - 3 * esdf::largestPositionSigma(relative_cov);
  return baseline > 0 ? baseline * m.relative.depth_per_baseline : 0.0;
}

}  // namespace urbanslam::slam
