#pragma once
// Everything a data source yields, one record at a time, in file order. Odometry is always an
// accumulated pose in the odometry frame (rawlog actions carry increments; readers chain them),
// so consumers never care which layout the file had.
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::io {

struct OdometryReading {
  double timestamp = 0;
  common::Pose2 pose;  // wheel odometry, accumulated (raw: never a corrected pose)
};

// Speed and steering of a car-like vehicle (Victoria Park DRS: encoder speed, steering angle).
struct DriveReading {
  double timestamp = 0;
  double speed_mps = 0;
  double steering_rad = 0;
};

// A calibrated camera, level on the vehicle: pinhole intrinsics (OpenCV's convention: the centre
// of the top-left pixel is (0, 0)) of the image as delivered, and the camera's pose in the
// vehicle frame, its heading being the direction of the optical axis. Enough to turn two images
// into a planar relative pose of the vehicle (vision_loop/PlanarRelativePose.h).
struct CameraCalibration {
  double fx_px = 0, fy_px = 0, cx_px = 0, cy_px = 0;
  common::Pose2 mount;
  bool operator==(const CameraCalibration& o) const {
    return fx_px == o.fx_px && fy_px == o.fy_px && cx_px == o.cx_px && cy_px == o.cy_px && mount.x == o.mount.x &&
           mount.y == o.mount.y && mount.phi == o.mount.phi;
  }
};

// 8-bit grayscale image. Pixels are loaded eagerly by the readers (images stored externally
// beside a rawlog are resolved against the rawlog's "<name>_Images" folder).
struct CameraImage {
  double timestamp = 0;
  std::string label;
  std::string source;  // file name the image came from, or "" when embedded
  int width = 0, height = 0;
  std::shared_ptr<const std::vector<uint8_t>> pixels;  // row-major, width*height
  std::optional<CameraCalibration> calibration;        // when the log or the simulator gives one
};

// A position fix in local metres (Victoria Park's GPS.txt).
struct GpsFix {
  double timestamp = 0;
  double x_m = 0, y_m = 0;
};

// A pose of a reference trajectory (e.g. the corrected pose of a Freiburg corrected log). Never
// used as odometry; evaluation and training read it.
struct ReferencePose {
  double timestamp = 0;
  common::Pose2 pose;
};

using Measurement = std::variant<LaserScan, OdometryReading, DriveReading, CameraImage, GpsFix, ReferencePose>;

double timestampOf(const Measurement& m);

}  // namespace urbanslam::io
