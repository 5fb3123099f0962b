#pragma once
// Conversions between our measurement structs and MRPT's observation classes. Private to io:
// only the rawlog reader/writer and the map writers include MRPT headers.
#include <mrpt/obs/CObservation.h>
#include <mrpt/img/CImage.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <optional>

#include "urbanslam/io/Measurements.h"

namespace urbanslam::io::detail {

// Labels used for the measurement kinds that MRPT has no dedicated class for.
constexpr const char* kDriveLabel = "DRIVE";          // CObservationRawDAQ: AIN_double = {speed, steering}
constexpr const char* kGpsLabel = "GPS_LOCAL";        // CObservationRobotPose: local metres
constexpr const char* kReferenceLabel = "REFERENCE";  // CObservationRobotPose: reference trajectory

mrpt::Clock::time_point toMrptTime(double t);
double fromMrptTime(const mrpt::Clock::time_point& t);

mrpt::obs::CObservation2DRangeScan::Ptr toMrptScan(const LaserScan& s);
// MRPT deserialises numbers and flags as raw bytes, so a corrupt entry holds NaN, huge values or
// a bool whose byte is neither 0 nor 1 (reading it is undefined behaviour). These apply the text
// readers' bounds (common/Numbers.h) and throw common::InputError naming `where` and `what`.
double checkedCoordinate(double v, const std::string& where, const char* what);  // |v| <= kMaxCoordinate
double checkedMagnitude(double v, const std::string& where, const char* what);   // |v| <= kMaxMagnitude
bool checkedFlag(const bool& flag, const std::string& where, const char* what);
// Throws common::InputError (with `where`) for an empty scan, a NaN/negative valid range, or a
// non-finite or out-of-range aperture, maximum range or sensor pose.
LaserScan fromMrptScan(const mrpt::obs::CObservation2DRangeScan& o, const std::string& where);

// Any measurement as an MRPT observation.
mrpt::obs::CObservation::Ptr toMrpt(const Measurement& m);

// A camera's calibration as MRPT's CObservationImage holds it: intrinsics in cameraParams, and
// cameraPose in MRPT's camera frame (+Z the optical axis, +X right, +Y down) on the vehicle.
void toMrptCamera(const CameraCalibration& c, int width, int height, mrpt::img::TCamera& params, mrpt::poses::CPose3D& pose);
// The calibration of an image `width` x `height`, or none when the log did not set one (fx or fy
// not positive) or the camera is not level (optical axis or rows tilted more than 30 degrees):
// the planar relative pose needs a level camera. Throws common::InputError (with `where`) for
// non-finite or out-of-range values.
std::optional<CameraCalibration> fromMrptCamera(const mrpt::img::TCamera& params, const mrpt::poses::CPose3D& pose, int width,
                                                int height, const std::string& where);

// An MRPT image (colour or gray, embedded or stored externally) as our 8-bit gray CameraImage.
// Throws common::InputError (with `where`) when an external image cannot be loaded.
CameraImage toGray(const mrpt::img::CImage& src, double t, const std::string& label, const std::string& where);

}  // namespace urbanslam::io::detail
