#include "urbanslam/io/VictoriaParkReader.h"

#include <cmath>
#include <filesystem>
#include <optional>

#include "TextScanner.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::io {

using common::InputError;
namespace fs = std::filesystem;

namespace {

constexpr int kBeams = 361;

bool isZip(const std::string& path) { return fs::path(path).extension() == ".zip"; }

std::unique_ptr<detail::TextScanner> openPart(const std::string& path, const std::string& file) {
  if (isZip(path)) return std::make_unique<detail::TextScanner>(detail::openZipEntry(path, file), path + ":" + file);
  const std::string p = (fs::path(path) / file).string();
  if (!fs::exists(p)) throw InputError(p + ": missing (a Victoria Park folder needs LASER.txt, DRS.txt, GPS.txt)");
  return std::make_unique<detail::TextScanner>(detail::openGzFile(p), p);
}

}  // namespace

struct VictoriaParkReader::Impl {
  VictoriaParkGeometry geo;
  std::unique_ptr<detail::TextScanner> laser, drs, gps;
  std::optional<Measurement> next_laser, next_drs, next_gps;
  long laser_records = 0;
  std::vector<std::string> fields;
  std::string token, line;

  void readLaser() {
    next_laser.reset();
    if (!laser->nextToken(token)) return;
    const std::string where = laser->name() + ": record " + std::to_string(laser_records + 1);
    LaserScan s;
    s.timestamp = detail::parseNumber(token, where, "time");
    s.label = "LASER";
    s.ranges.resize(kBeams);
    s.valid.resize(kBeams);
    for (int k = 0; k < kBeams; ++k) {
      if (!laser->nextToken(token)) throw InputError(where + ": truncated (" + std::to_string(k) + " of 361 ranges)");
      const double r = detail::parseNumber(token, where, "range");
      if (r < 0) throw InputError(where + ": negative range " + token);
      s.ranges[static_cast<size_t>(k)] = static_cast<float>(r);
      s.valid[static_cast<size_t>(k)] = r > 0 && r < geo.max_range_m ? 1 : 0;
    }
    s.angle_min_rad = -M_PI / 2;
    s.angle_increment_rad = 0.5 * M_PI / 180;
    s.max_range_m = geo.max_range_m;
    s.sensor_pose = {geo.laser_x_m, geo.laser_y_m, 0};
    ++laser_records;
    next_laser = std::move(s);
  }

  // Next non-empty line split into fields, or false at the end.
  bool readFields(detail::TextScanner& t, size_t need, const char* what) {
    while (t.nextLine(line)) {
      detail::splitFields(line, fields);
      if (fields.empty()) continue;
      if (fields.size() < need) throw InputError(t.name() + ":" + std::to_string(t.lineNumber()) + ": truncated " + what + " line");
      return true;
    }
    return false;
  }

  void readDrs() {
    next_drs.reset();
    if (!readFields(*drs, 3, "DRS")) return;
    const std::string where = drs->name() + ":" + std::to_string(drs->lineNumber());
    next_drs = DriveReading{detail::parseNumber(fields[0], where, "time"), detail::parseCoordinate(fields[1], where, "speed"),
                            detail::parseCoordinate(fields[2], where, "steering")};
  }

  void readGps() {
    next_gps.reset();
    if (!readFields(*gps, 3, "GPS")) return;
    const std::string where = gps->name() + ":" + std::to_string(gps->lineNumber());
    next_gps = GpsFix{detail::parseNumber(fields[0], where, "time"), detail::parseCoordinate(fields[2], where, "x"),
                      detail::parseCoordinate(fields[1], where, "y")};
  }
};

bool VictoriaParkReader::looksLike(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return fs::exists(fs::path(path) / "LASER.txt");
  return isZip(path);
}

VictoriaParkReader::VictoriaParkReader(const std::string& path, VictoriaParkGeometry geometry)
    : DataSource(path), impl_(std::make_unique<Impl>()) {
  impl_->geo = geometry;
  impl_->laser = openPart(path, "LASER.txt");
  impl_->drs = openPart(path, "DRS.txt");
  impl_->gps = openPart(path, "GPS.txt");
  impl_->readLaser();
  impl_->readDrs();
  impl_->readGps();
}

VictoriaParkReader::~VictoriaParkReader() = default;

bool VictoriaParkReader::next(Measurement& out) {
  // Merge the three time-sorted files; on equal times drive data first, so a scan sees the
  // latest speed and steering.
  std::optional<Measurement>* best = nullptr;
  for (auto* c : {&impl_->next_drs, &impl_->next_gps, &impl_->next_laser})
    if (c->has_value() && (!best || timestampOf(**c) < timestampOf(**best))) best = c;
  if (!best) return false;
  out = std::move(**best);
  if (best == &impl_->next_laser)
    impl_->readLaser();
  else if (best == &impl_->next_drs)
    impl_->readDrs();
  else
    impl_->readGps();
  return true;
}

double VictoriaParkReader::progress() const { return impl_->laser->progress(); }

}  // namespace urbanslam::io
