#pragma once
// A stream of measurements from a log file, read incrementally (a multi-GB rawlog is never held
// in memory). openDataSource() picks the reader from the file's content, not its name.
#include <memory>
#include <string>

#include "urbanslam/io/Measurements.h"

namespace urbanslam::io {

class DataSource {
 public:
  virtual ~DataSource() = default;
  // Next measurement in file order; false at the end. Throws common::InputError naming the file
  // (and line or entry) on truncated or corrupt input.
  virtual bool next(Measurement& out) = 0;
  // Fraction of the input consumed, in [0,1], for progress bars (approximate).
  virtual double progress() const = 0;
  // Short description of the format, e.g. "MRPT rawlog (observations)" or "CARMEN log (corrected)".
  virtual std::string format() const = 0;
  const std::string& path() const { return path_; }

 protected:
  explicit DataSource(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

enum class LogFormat { Unknown, MrptRawlog, Carmen, Gfs, VictoriaPark, ImageFolder };

// Detects the format of a file or folder. Throws common::InputError for a missing path.
LogFormat detectLogFormat(const std::string& path);

// Opens any supported input: MRPT rawlog (both layouts, gzipped or not), CARMEN log (gzipped or
// not, raw or Freiburg-"corrected"), GMapping gfs output, Victoria Park (folder with LASER.txt/DRS.txt/GPS.txt, or
// victoria_park_ascii.zip), a folder of images (camera only). Throws common::InputError for a missing or unrecognised input.
std::unique_ptr<DataSource> openDataSource(const std::string& path);

}  // namespace urbanslam::io
