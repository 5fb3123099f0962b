#include "urbanslam/io/GfsReader.h"

#include <cmath>

#include "CarmenBeams.h"
#include "TextScanner.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

using common::InputError;
using common::Pose2;
using detail::parseCoordinate;
using detail::parseInteger;
using detail::parseNumber;

bool GfsReader::sniff(const std::string& head) {
  // PARAM and ODOM also start CARMEN logs; these tags are GMapping's own.
  for (const char* tag : {"LASER_READING ", "ODO_UPDATE ", "SM_UPDATE ", "PARAM outfilename"})
    if (head.find(tag) != std::string::npos) return true;
  return false;
}

GfsReader::GfsReader(const std::string& path)
    : DataSource(path), text_(std::make_unique<detail::TextScanner>(detail::openGzFile(path), path)) {}

GfsReader::~GfsReader() = default;

double GfsReader::progress() const { return text_->progress(); }

std::string GfsReader::format() const { return "GMapping gfs log (raw odometry, full-precision timestamps)"; }

bool GfsReader::next(Measurement& out) {
  return detail::nextRecord(*text_, pending_, pending_pos_, out, [this](const std::string& l) { parseLine(l); });
}

// Odometry goes out once per time, in time order (a time already covered is not repeated).
void GfsReader::emitOdometry(double t, const Pose2& pose) {
  if (any_odometry_ && t <= last_odometry_time_) return;
  pending_.emplace_back(OdometryReading{t, pose});
  any_odometry_ = true;
  last_odometry_time_ = t;
}

bool GfsReader::parseLine(const std::string& line) {
  detail::splitFields(line, fields_);
  if (fields_.empty() || fields_[0][0] == '#') return false;
  const auto& f = fields_;
  const std::string where = path_ + ":" + std::to_string(text_->lineNumber());
  if (f[0] == "PARAM" && f.size() >= 3 && f[1] == "maxrange") {
    const double r = parseNumber(f[2], where, "maxrange");
    if (r > 0) max_range_m_ = r;
  } else if (f[0] == "ODOM") {
    if (f.size() < 5) throw InputError(where + ": truncated ODOM line (" + std::to_string(f.size()) + " fields, need 5)");
    const Pose2 p{parseCoordinate(f[1], where, "x"), parseCoordinate(f[2], where, "y"),
                  common::wrapToPi(parseCoordinate(f[3], where, "theta"))};
    const double t = parseNumber(f[4], where, "timestamp");
    // This line's pose was measured at the previous line's time.
    if (!any_odometry_)
      emitOdometry(t, p);  // GMapping starts from the first reading's own pose
    else if (have_held_)
      emitOdometry(held_time_, p);
    have_held_ = true;
    held_time_ = t;
  } else if (f[0] == "LASER_READING") {
    if (f.size() < 2) throw InputError(where + ": truncated LASER_READING line");
    const long n = parseInteger(f[1], where, "beam count");
    if (n <= 0 || n > 100000) throw InputError(where + ": invalid beam count " + f[1]);
    const size_t nn = static_cast<size_t>(n);
    if (f.size() < nn + 6)
      throw InputError(where + ": truncated LASER_READING line (" + std::to_string(f.size()) + " fields, need " + std::to_string(nn + 6) +
                       ")");
    LaserScan scan;
    scan.label = "FLASER";
    scan.max_range_m = max_range_m_;
    detail::parseRanges(f, 2, nn, max_range_m_, where, scan.ranges, scan.valid);
    detail::setBeamGeometry(scan, -M_PI / 2, detail::resolutionForBeams(n), Pose2{});
    scan.timestamp = parseNumber(f[nn + 5], where, "timestamp");
    // The scan's pose is the odometry at its time: it completes the held ODOM line of that time.
    const Pose2 pose{parseCoordinate(f[nn + 2], where, "x"), parseCoordinate(f[nn + 3], where, "y"),
                     common::wrapToPi(parseCoordinate(f[nn + 4], where, "theta"))};
    emitOdometry(scan.timestamp, pose);
    if (have_held_ && held_time_ <= scan.timestamp) have_held_ = false;
    pending_.emplace_back(std::move(scan));
  }
  return true;
}

}  // namespace urbanslam::io
