#include "MrptConversions.h"

#include <mrpt/img/CImage.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CObservationRawDAQ.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Numbers.h"
#include "urbanslam/io/ImageHeader.h"

namespace urbanslam::io::detail {

using common::InputError;

mrpt::Clock::time_point toMrptTime(double t) { return mrpt::Clock::fromDouble(t); }
double fromMrptTime(const mrpt::Clock::time_point& t) { return mrpt::Clock::toDouble(t); }

mrpt::obs::CObservation2DRangeScan::Ptr toMrptScan(const LaserScan& s) {
  auto o = mrpt::obs::CObservation2DRangeScan::Create();
  o->timestamp = toMrptTime(s.timestamp);
  o->sensorLabel = s.label;
  const size_t n = s.ranges.size();
  o->resizeScan(n);
  for (size_t i = 0; i < n; ++i) {
    o->setScanRange(i, s.ranges[i]);
    o->setScanRangeValidity(i, s.valid[i] != 0);
  }
  // MRPT's beams are symmetric about the sensor's x axis; any offset goes into the yaw.
  const double span = s.angle_increment_rad * static_cast<double>(n > 0 ? n - 1 : 0);
  o->aperture = static_cast<float>(std::abs(span));
  o->rightToLeft = s.angle_increment_rad >= 0;
  const double mid = s.angle_min_rad + span / 2;
  o->sensorPose = mrpt::poses::CPose3D(s.sensor_pose.x, s.sensor_pose.y, 0, s.sensor_pose.phi + mid, 0, 0);
  o->maxRange = static_cast<float>(s.max_range_m);
  return o;
}

namespace {

[[noreturn]] void throwBadValue(const std::string& where, const char* what, double v) {
  throw InputError(where + ": corrupt entry: " + what + " is " + std::to_string(v));
}

}  // namespace

double checkedCoordinate(double v, const std::string& where, const char* what) {
  if (!(std::abs(v) <= common::kMaxCoordinate)) throwBadValue(where, what, v);
  return v;
}

double checkedMagnitude(double v, const std::string& where, const char* what) {
  if (!(std::abs(v) <= common::kMaxMagnitude)) throwBadValue(where, what, v);
  return v;
}

bool checkedFlag(const bool& flag, const std::string& where, const char* what) {
  uint8_t byte = 0;
  std::memcpy(&byte, &flag, 1);
  if (byte > 1) throw InputError(where + ": corrupt entry: " + what + " flag byte is " + std::to_string(byte));
  return byte == 1;
}

LaserScan fromMrptScan(const mrpt::obs::CObservation2DRangeScan& o, const std::string& where) {
  const bool right_to_left = checkedFlag(o.rightToLeft, where, "laser scan rightToLeft");
  const double aperture = o.aperture;
  if (!(aperture >= 0 && aperture <= 2 * M_PI + 1e-3)) throwBadValue(where, "laser scan aperture", aperture);
  if (!(o.maxRange > 0 && o.maxRange <= common::kMaxMagnitude)) throwBadValue(where, "laser scan maximum range", o.maxRange);
  const auto& sp = o.sensorPose;
  checkedCoordinate(sp.x(), where, "laser sensor pose x");
  checkedCoordinate(sp.y(), where, "laser sensor pose y");
  checkedCoordinate(sp.yaw(), where, "laser sensor pose yaw");
  LaserScan s;
  s.timestamp = fromMrptTime(o.timestamp);
  s.label = o.sensorLabel;
  const size_t n = o.getScanSize();
  if (n == 0) throw InputError(where + ": empty laser scan (0 beams)");
  s.ranges.resize(n);
  s.valid.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float r = o.getScanRange(i);
    const bool ok = o.getScanRangeValidity(i);
    if (ok && (!std::isfinite(r) || r < 0))
      throw InputError(where + ": laser beam " + std::to_string(i) + " has an invalid range (" + std::to_string(r) + ")");
    s.ranges[i] = std::isfinite(r) ? r : 0.f;
    s.valid[i] = ok && r > 0 && r < o.maxRange ? 1 : 0;
  }
  const double step = n > 1 ? aperture / static_cast<double>(n - 1) : 0.0;
  s.angle_increment_rad = right_to_left ? step : -step;
  s.angle_min_rad = right_to_left ? -aperture / 2.0 : aperture / 2.0;
  s.max_range_m = o.maxRange;
  s.sensor_pose = {o.sensorPose.x(), o.sensorPose.y(), o.sensorPose.yaw()};
  return s;
}

namespace {

struct ToMrpt {
  mrpt::obs::CObservation::Ptr operator()(const LaserScan& s) const { return toMrptScan(s); }
  mrpt::obs::CObservation::Ptr operator()(const OdometryReading& m) const {
    auto o = mrpt::obs::CObservationOdometry::Create();
    o->timestamp = toMrptTime(m.timestamp);
    o->sensorLabel = "ODOMETRY";
    o->odometry = mrpt::poses::CPose2D(m.pose.x, m.pose.y, m.pose.phi);
    o->hasEncodersInfo = false;
    o->hasVelocities = false;
    return o;
  }
  mrpt::obs::CObservation::Ptr operator()(const DriveReading& m) const {
    auto o = mrpt::obs::CObservationRawDAQ::Create();
    o->timestamp = toMrptTime(m.timestamp);
    o->sensorLabel = kDriveLabel;
    o->AIN_double = {m.speed_mps, m.steering_rad};
    return o;
  }
  mrpt::obs::CObservation::Ptr operator()(const CameraImage& m) const {
    auto o = mrpt::obs::CObservationImage::Create();
    o->timestamp = toMrptTime(m.timestamp);
    o->sensorLabel = m.label;
    if (m.calibration) toMrptCamera(*m.calibration, m.width, m.height, o->cameraParams, o->cameraPose);
    o->image = mrpt::img::CImage(m.width, m.height, mrpt::img::CH_GRAY);
    for (int r = 0; r < m.height; ++r)
      std::copy_n(m.pixels->data() + static_cast<size_t>(r) * static_cast<size_t>(m.width), static_cast<size_t>(m.width),
                  o->image.ptrLine<uint8_t>(static_cast<unsigned>(r)));
    return o;
  }
  mrpt::obs::CObservation::Ptr operator()(const GpsFix& m) const {
    auto o = mrpt::obs::CObservationRobotPose::Create();
    o->timestamp = toMrptTime(m.timestamp);
    o->sensorLabel = kGpsLabel;
    o->pose.mean = mrpt::poses::CPose3D(m.x_m, m.y_m, 0, 0, 0, 0);
    return o;
  }
  mrpt::obs::CObservation::Ptr operator()(const ReferencePose& m) const {
    auto o = mrpt::obs::CObservationRobotPose::Create();
    o->timestamp = toMrptTime(m.timestamp);
    o->sensorLabel = kReferenceLabel;
    o->pose.mean = mrpt::poses::CPose3D(m.pose.x, m.pose.y, 0, m.pose.phi, 0, 0);
    return o;
  }
};

}  // namespace

mrpt::obs::CObservation::Ptr toMrpt(const Measurement& m) { return std::visit(ToMrpt{}, m); }

void toMrptCamera(const CameraCalibration& c, int width, int height, mrpt::img::TCamera& params, mrpt::poses::CPose3D& pose) {
  params.ncols = static_cast<uint32_t>(width);
  params.nrows = static_cast<uint32_t>(height);
  params.setIntrinsicParamsFromValues(c.fx_px, c.fy_px, c.cx_px, c.cy_px);
  // MRPT's camera frame looks along +Z: a level camera whose optical axis has heading psi on the
  // vehicle is yaw psi - 90 deg, roll -90 deg.
  pose = mrpt::poses::CPose3D(c.mount.x, c.mount.y, 0, c.mount.phi - M_PI / 2, 0, -M_PI / 2);
}

std::optional<CameraCalibration> fromMrptCamera(const mrpt::img::TCamera& params, const mrpt::poses::CPose3D& pose, int width,
                                                int height, const std::string& where) {
  if (!(params.fx() > 0) || !(params.fy() > 0)) return std::nullopt;
  CameraCalibration c;
  c.fx_px = checkedMagnitude(params.fx(), where, "camera fx");
  c.fy_px = checkedMagnitude(params.fy(), where, "camera fy");
  c.cx_px = checkedMagnitude(params.cx(), where, "camera cx");
  c.cy_px = checkedMagnitude(params.cy(), where, "camera cy");
  // Intrinsics calibrated at another resolution scale with the image.
  if (params.ncols > 0 && params.nrows > 0 && (params.ncols != static_cast<uint32_t>(width) || params.nrows != static_cast<uint32_t>(height))) {
    const double sx = static_cast<double>(width) / params.ncols, sy = static_cast<double>(height) / params.nrows;
    c.fx_px *= sx;
    c.cx_px = (c.cx_px + 0.5) * sx - 0.5;
    c.fy_px *= sy;
    c.cy_px = (c.cy_px + 0.5) * sy - 0.5;
  }
  const auto r = pose.getRotationMatrix();
  const double axis_x = r(0, 2), axis_y = r(1, 2), axis_z = r(2, 2), right_z = r(2, 0);
  if (!std::isfinite(axis_x) || !std::isfinite(axis_y) || std::abs(axis_z) > 0.5 || std::abs(right_z) > 0.5) return std::nullopt;
  c.mount = {checkedCoordinate(pose.x(), where, "camera x"), checkedCoordinate(pose.y(), where, "camera y"), std::atan2(axis_y, axis_x)};
  return c;
}

CameraImage toGray(const mrpt::img::CImage& src, double t, const std::string& label, const std::string& where) {
  mrpt::img::CImage gray;
  // An externally stored image is loaded on demand here: its header is checked first.
  if (src.isExternallyStored()) checkImageFile(src.getExternalStorageFileAbsolutePath());
  try {
    src.grayscale(gray);  // loads an externally stored image on demand
  } catch (const std::exception& e) {
    throw InputError(where + ": cannot load image (" + std::string(e.what()) + ")");
  }
  CameraImage img;
  img.timestamp = t;
  img.label = label;
  img.source = src.isExternallyStored() ? src.getExternalStorageFile() : std::string();
  img.width = static_cast<int>(gray.getWidth());
  img.height = static_cast<int>(gray.getHeight());
  auto px = std::make_shared<std::vector<uint8_t>>(static_cast<size_t>(img.width) * static_cast<size_t>(img.height));
  for (int r = 0; r < img.height; ++r)
    std::copy_n(gray.ptrLine<uint8_t>(static_cast<unsigned>(r)), static_cast<size_t>(img.width),
                px->data() + static_cast<size_t>(r) * static_cast<size_t>(img.width));
  img.pixels = std::move(px);
  return img;
}

}  // namespace urbanslam::io::detail
