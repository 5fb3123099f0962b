#include "urbanslam/io/CarmenReader.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <variant>

#include "CarmenBeams.h"
#include "TextScanner.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

using common::InputError;
using common::Pose2;
using detail::parseCoordinate;
using detail::parseInteger;
using detail::parseNumber;
using detail::resolutionForBeams;
using detail::setBeamGeometry;

namespace {

bool samePose(const Pose2& a, const Pose2& b) {
  return std::abs(a.x - b.x) < 1e-9 && std::abs(a.y - b.y) < 1e-9 && std::abs(common::wrapToPi(a.phi - b.phi)) < 1e-9;
}

// The step of a number as printed: "2670.16" -> 0.01, "1.13487e+09" -> 1e4, "42" -> 1.
double printedResolution(const std::string& token) {
  const size_t e = token.find_first_of("eE");
  const std::string mantissa = token.substr(0, e);
  const size_t dot = mantissa.find('.');
  const long decimals = dot == std::string::npos ? 0 : static_cast<long>(mantissa.size() - dot - 1);
  // In double: an exponent as written can be as large as a long holds (strtol saturates).
  const double exponent = e == std::string::npos ? 0.0 : static_cast<double>(std::strtol(token.c_str() + e + 1, nullptr, 10));
  return std::pow(10.0, exponent - static_cast<double>(decimals));
}

// Significant digits as printed: "2670.16" -> 6, "0.0250" -> 3.
int significantDigits(const std::string& token) {
  int n = 0;
  bool leading = true;
  for (char c : token.substr(0, token.find_first_of("eE"))) {
    if (c < '0' || c > '9') continue;
    if (leading && c == '0') continue;
    leading = false;
    ++n;
  }
  return n;
}

// ROBOTLASER1 type start_angle fov resolution max_range accuracy remission_mode n r1..rn
//   m rem1..remm laser_x laser_y laser_theta robot_x robot_y robot_theta tv rv fwd side turn
//   timestamp hostname logger_timestamp
// Where its variable-length parts put the fields after them: `tail` is the index of laser_x (the
// robot pose at tail + 3, the timestamp at tail + 11). None when a count is negative or the line
// is too short for the counts it declares.
struct RobotLaserLayout {
  size_t beams = 0, tail = 0;
};
std::optional<RobotLaserLayout> robotLaserLayout(const std::vector<std::string>& f, const std::string& where) {
  if (f.size() < 9) return std::nullopt;
  const long n = parseInteger(f[8], where, "beam count");
  if (n < 0 || f.size() < 10 + static_cast<size_t>(n)) return std::nullopt;
  const long m = parseInteger(f[9 + static_cast<size_t>(n)], where, "remission count");
  if (m < 0) return std::nullopt;
  const size_t tail = 10 + static_cast<size_t>(n) + static_cast<size_t>(m);
  if (f.size() < tail + 14) return std::nullopt;
  return RobotLaserLayout{static_cast<size_t>(n), tail};
}

// A fixed-point format keeps trailing zeros ("5.20"); %g drops them ("5.2").
bool hasTrailingZero(const std::string& token) {
  const std::string mantissa = token.substr(0, token.find_first_of("eE"));
  return mantissa.find('.') != std::string::npos && mantissa.back() == '0';
}

}  // namespace

bool CarmenReader::sniff(const std::string& head) {
  for (const char* tag : {"FLASER ", "ODOM ", "ROBOTLASER1 ", "RLASER ", "PARAM ", "# message formats", "RAWLASER"})
    if (head.find(tag) != std::string::npos) return true;
  return false;
}

CarmenReader::CarmenReader(const std::string& path) : DataSource(path) {
  prescan();
  text_ = std::make_unique<detail::TextScanner>(detail::openGzFile(path), path);
}

CarmenReader::~CarmenReader() = default;

// Reads the head of the log once to learn what the stream cannot tell until too late: whether
// it is a corrected log (NEFF lines, anchors that jump) and whether it has timestamps.
void CarmenReader::prescan() {
  detail::TextScanner t(detail::openGzFile(path_), path_);
  std::string line;
  std::vector<std::string> f;
  bool after_scan = false, any_ts = false, any_scan = false;
  long scans_seen = 0, repeated_ts = 0;
  double last_scan_ts = -1;
  Pose2 scan_pose, prev_odom;
  bool have_prev_odom = false;
  // Front and rear scans of one instant legitimately share a time: only front scans count repeats.
  const auto noteScanStamp = [&](const std::string& token, const std::string& where, bool front) {
    any_scan = true;
    const double ts = parseNumber(token, where, "timestamp");
    if (ts != 0) any_ts = true;
    noteStampFormat(token);
    if (front) {
      repeated_ts += ts == last_scan_ts ? 1 : 0;
      last_scan_ts = ts;
      ++scans_seen;
    }
  };
  for (int k = 0; k < 50000 && t.nextLine(line); ++k) {
    detail::splitFields(line, f);
    if (f.empty()) continue;
    const std::string where = path_ + ":" + std::to_string(t.lineNumber());
    if (f[0] == "NEFF") info_.corrected = true;
    if (f[0] == "PARAM" && f.size() >= 3) handleParam(f);
    if (f[0] == "ODOM" && f.size() >= 4) {
      any_odom_lines_ = true;
      const Pose2 p{parseCoordinate(f[1], where, "x"), parseCoordinate(f[2], where, "y"), parseCoordinate(f[3], where, "theta")};
      // An anchor that differs from the odometry just before it is a corrected pose.
      if (after_scan && samePose(p, scan_pose) && have_prev_odom && !samePose(p, prev_odom)) info_.corrected = true;
      prev_odom = p;
      have_prev_odom = true;
      if (f.size() >= 8) noteStampFormat(f[7]);
    }
    after_scan = false;
    if ((f[0] == "FLASER" || f[0] == "RLASER") && f.size() >= 2) {
      const long n = parseInteger(f[1], where, "beam count");
      if (n >= 0 && f.size() >= static_cast<size_t>(n) + 9) {
        scan_pose = {parseCoordinate(f[static_cast<size_t>(n) + 2], where, "x"), parseCoordinate(f[static_cast<size_t>(n) + 3], where, "y"),
                     parseCoordinate(f[static_cast<size_t>(n) + 4], where, "theta")};
        after_scan = f[0] == "FLASER";
        noteScanStamp(f[static_cast<size_t>(n) + 8], where, f[0] == "FLASER");
      }
    }
    if (f[0] == "ROBOTLASER1") {
      if (const auto l = robotLaserLayout(f, where)) {
        const size_t k = l->tail;
        scan_pose = {parseCoordinate(f[k + 3], where, "robot_x"), parseCoordinate(f[k + 4], where, "robot_y"),
                     parseCoordinate(f[k + 5], where, "robot_theta")};
        after_scan = true;
        noteScanStamp(f[k + 11], where, true);
      }
    }
  }
  // Some logs print timestamps with 6 significant digits (csail: 1.13486e+09), so most scans
  // share one: such timestamps cannot order anything, and the scan index is used instead.
  info_.has_timestamps = (any_ts || !any_scan) && repeated_ts * 5 < scans_seen;
}

void CarmenReader::handleParam(const std::vector<std::string>& f) {
  // Only the geometry we need; the many other PARAMs are robot/simulator settings.
  const auto num = [&](double& dst) {
    if (const auto v = common::parseDecimal(f[2]); v && std::abs(*v) <= common::kMaxCoordinate) dst = *v;
  };
  if (f[1] == "robot_front_laser_max")
    num(info_.front_max_range_m);
  else if (f[1] == "robot_rear_laser_max")
    num(info_.rear_max_range_m);
  else if (f[1] == "robot_frontlaser_offset")
    num(info_.front_offset_m);
  else if (f[1] == "robot_rearlaser_offset")
    num(info_.rear_offset_m);
}

double CarmenReader::progress() const { return text_ ? text_->progress() : 0.0; }

std::string CarmenReader::format() const {
  std::string s = info_.corrected ? "CARMEN log (corrected: FLASER poses are the reference)" : "CARMEN log";
  if (!info_.has_timestamps) s += ", no usable timestamps: scan index used as time";
  return s;
}

// Logs without timestamps get the scan count as time: scan k at k seconds, the odometry read
// before it at the same time, so the order of the file is kept.
double CarmenReader::stamp(double log_ts, bool is_scan) {
  if (info_.has_timestamps) return log_ts;
  return static_cast<double>(scans_ + (is_scan ? 0 : 1));
}

// Logs written with 6 significant digits (the Freiburg corrected logs) print times after 1000 s
// to 10 ms, and the Intel log's odometry arrives in bursts: up to 11 readings, 0.57 m of travel,
// share one printed time. Such a run of lines is held back until the time changes and spread
// evenly, in file order, over the interval the printed value stands for (t +- step/2), so the
// trajectory is ordered in time and can be interpolated at the raw log's microsecond times
// (Intel relation error 0.0562 -> 0.0477 m).
bool CarmenReader::next(Measurement& out) {
  while (ready_pos_ >= ready_.size()) {
    ready_.clear();
    ready_pos_ = 0;
    std::string line;
    if (!text_->nextLine(line)) {
      releaseRun();
      if (ready_.empty()) return false;
      break;
    }
    pending_.clear();
    parseLine(line);
    if (pending_.empty()) continue;
    const double t = timestampOf(pending_.front());
    const bool same = !run_.empty() && t == run_stamp_ && run_.size() < kMaxRunLines;
    if (!run_.empty() && !same) releaseRun();
    if (run_.empty()) {
      run_stamp_ = t;
      run_step_ = line_step_;
    }
    // A scan shares the instant of the reading before it: corrected logs stamp each FLASER with
    // the time of the ODOM line it was paired with, and a RLASER with its FLASER's time.
    if (same && line_is_scan_) {
      for (auto& m : pending_) run_.back().push_back(std::move(m));
    } else {
      run_.push_back(std::move(pending_));
    }
    pending_ = {};
    if (!info_.has_timestamps) releaseRun();  // scan-index times are not printed values
  }
  out = std::move(ready_[ready_pos_++]);
  return true;
}

void CarmenReader::releaseRun() {
  const size_t k = run_.size();
  for (size_t i = 0; i < k; ++i) {
    const double t = run_stamp_ - run_step_ / 2 + run_step_ * (static_cast<double>(i) + 0.5) / static_cast<double>(k);
    for (auto& m : run_[i]) {
      if (k > 1 && info_.has_timestamps && run_step_ > 0) std::visit([t](auto& v) { v.timestamp = t; }, m);
      ready_.push_back(std::move(m));
    }
  }
  run_.clear();
}

void CarmenReader::noteStampFormat(const std::string& token) {
  stamp_fixed_point_ = stamp_fixed_point_ || hasTrailingZero(token);
  stamp_digits_ = std::max(stamp_digits_, significantDigits(token));
}

double CarmenReader::lineStamp(const std::string& token, const std::string& where, bool is_scan) {
  const double ts = parseNumber(token, where, "timestamp");
  line_step_ = printedResolution(token);
  // %g drops trailing zeros: with 6 significant digits "2162.6" is 2162.60, a 10 ms step.
  if (!stamp_fixed_point_ && stamp_digits_ > 0 && ts != 0)
    line_step_ = std::min(line_step_, std::pow(10.0, std::floor(std::log10(std::abs(ts))) + 1 - stamp_digits_));
  line_is_scan_ = is_scan;
  return stamp(ts, is_scan);
}

bool CarmenReader::parseLine(const std::string& line) {
  detail::splitFields(line, fields_);
  if (fields_.empty() || fields_[0][0] == '#') return false;
  const std::string where = path_ + ":" + std::to_string(text_->lineNumber());
  const std::string& tag = fields_[0];
  if (tag == "ODOM")
    handleOdom(fields_, where);
  else if (tag == "FLASER")
    handleLaser(fields_, where, false);
  else if (tag == "RLASER")
    handleLaser(fields_, where, true);
  else if (tag == "ROBOTLASER1")
    handleRobotLaser(fields_, where);
  else if (tag == "PARAM" && fields_.size() >= 3)
    handleParam(fields_);
  // NEFF, SYNC, TRUEPOS, RAWLASER*, SONAR, ...: not used.
  // Only the ODOM line right after a scan can be an anchor (handlers set/clear the flag).
  if (tag != "ODOM" && tag != "FLASER" && tag != "RLASER" && tag != "ROBOTLASER1") last_was_scan_ = false;
  return true;
}

void CarmenReader::handleOdom(const std::vector<std::string>& f, const std::string& where) {
  // ODOM x y theta tv rv accel timestamp hostname logger_timestamp
  if (f.size() < 8) throw InputError(where + ": truncated ODOM line (" + std::to_string(f.size()) + " fields, need 8)");
  const Pose2 p{parseCoordinate(f[1], where, "x"), parseCoordinate(f[2], where, "y"),
                common::wrapToPi(parseCoordinate(f[3], where, "theta"))};
  const double ts = lineStamp(f[7], where, false);
  const bool anchor = last_was_scan_ && samePose(p, last_scan_pose_);
  last_was_scan_ = false;
  if (anchor && have_odom_) {
    // A re-anchor at the corrected pose starts a new segment; in a raw log it is a zero increment.
    last_odom_line_ = p;
    return;
  }
  if (!have_raw_) {
    raw_ = p;
    have_raw_ = true;
  } else {
    raw_ = common::compose(raw_, common::between(last_odom_line_, p));
  }
  last_odom_line_ = p;
  have_odom_ = true;
  pending_.emplace_back(OdometryReading{ts, raw_});
}

void CarmenReader::emitScan(LaserScan scan, const Pose2& log_pose, const Pose2& odom_pose) {
  if (info_.corrected) {
    pending_.emplace_back(ReferencePose{scan.timestamp, log_pose});
  } else if (!any_odom_lines_) {
    // Logs without ODOM lines carry the odometry only inside the laser messages.
    pending_.emplace_back(OdometryReading{scan.timestamp, odom_pose});
  }
  pending_.emplace_back(std::move(scan));
}

void CarmenReader::handleLaser(const std::vector<std::string>& f, const std::string& where, bool rear) {
  // FLASER n r1..rn x y theta odom_x odom_y odom_theta timestamp hostname logger_timestamp
  if (f.size() < 2) throw InputError(where + ": truncated laser line");
  const long n = parseInteger(f[1], where, "beam count");
  if (n <= 0 || n > 100000) throw InputError(where + ": invalid beam count " + f[1]);
  const size_t nn = static_cast<size_t>(n);
  if (f.size() < nn + 9)
    throw InputError(where + ": truncated laser line (" + std::to_string(f.size()) + " fields, need " + std::to_string(nn + 9) + ")");
  LaserScan scan;
  scan.label = rear ? "RLASER" : "FLASER";
  scan.max_range_m = rear ? info_.rear_max_range_m : info_.front_max_range_m;
  detail::parseRanges(f, 2, nn, scan.max_range_m, where, scan.ranges, scan.valid);
  const Pose2 pose{parseCoordinate(f[nn + 2], where, "x"), parseCoordinate(f[nn + 3], where, "y"),
                   common::wrapToPi(parseCoordinate(f[nn + 4], where, "theta"))};
  const Pose2 odom{parseCoordinate(f[nn + 5], where, "odom_x"), parseCoordinate(f[nn + 6], where, "odom_y"),
                   common::wrapToPi(parseCoordinate(f[nn + 7], where, "odom_theta"))};
  ++scans_;
  scan.timestamp = lineStamp(f[nn + 8], where, true);
  const Pose2 mount = rear ? Pose2{info_.rear_offset_m, 0, M_PI} : Pose2{info_.front_offset_m, 0, 0};
  setBeamGeometry(scan, -M_PI / 2, resolutionForBeams(n), mount);
  emitScan(std::move(scan), pose, odom);
  last_was_scan_ = !rear;
  last_scan_pose_ = pose;
}

void CarmenReader::handleRobotLaser(const std::vector<std::string>& f, const std::string& where) {
  if (f.size() < 9) throw InputError(where + ": truncated ROBOTLASER1 line");
  const long n = parseInteger(f[8], where, "beam count");
  if (n <= 0 || n > 100000) throw InputError(where + ": invalid beam count " + f[8]);
  const auto layout = robotLaserLayout(f, where);
  if (!layout) throw InputError(where + ": truncated ROBOTLASER1 line");
  const size_t nn = layout->beams, k = layout->tail;
  LaserScan scan;
  scan.label = "ROBOTLASER1";
  scan.max_range_m = parseNumber(f[5], where, "maximum_range");
  detail::parseRanges(f, 9, nn, scan.max_range_m, where, scan.ranges, scan.valid);
  const Pose2 laser{parseCoordinate(f[k], where, "laser_x"), parseCoordinate(f[k + 1], where, "laser_y"),
                    parseCoordinate(f[k + 2], where, "laser_theta")};
  const Pose2 robot{parseCoordinate(f[k + 3], where, "robot_x"), parseCoordinate(f[k + 4], where, "robot_y"),
                    common::wrapToPi(parseCoordinate(f[k + 5], where, "robot_theta"))};
  ++scans_;
  scan.timestamp = lineStamp(f[k + 11], where, true);
  setBeamGeometry(scan, parseCoordinate(f[2], where, "start_angle"), parseCoordinate(f[4], where, "resolution"),
                  common::between(robot, laser));
  emitScan(std::move(scan), robot, robot);
  last_was_scan_ = true;
  last_scan_pose_ = robot;
}

}  // namespace urbanslam::io
