#pragma once
// GMapping ".gfs" output logs, e.g. the Freiburg benchmark's mit-csail.corrected.gfs. They are
// the only logs in the benchmark that keep the raw log's full-precision timestamps, so the
// relation files apply to them directly.
//
//   ODOM x y theta t                    raw odometry at every laser reading GMapping received
//   LASER_READING n r1..rn x y theta t  the readings GMapping processed (a subset)
//   SM_UPDATE, ODO_UPDATE, RESAMPLE, NEFF, FRAME, PARAM: particle bookkeeping, not used
//
// GMapping writes each ODOM line before it updates its odometry, so an ODOM line carries the
// time of its reading but the pose of the reading before (a LASER_READING carries the pose of
// its own reading, which the next ODOM line repeats). The reader shifts the poses back by one
// line, so each odometry reading pairs a time with the pose measured at that time. This matters
// after odometry dropouts: at 1134864699.24 the ODOM line still repeats a pose 0.85 m and 50°
// old while the scan's own pose has it right.
#include <memory>
#include <string>
#include <vector>

#include "urbanslam/io/DataSource.h"

namespace urbanslam::io {

namespace detail {
class TextScanner;
}

class GfsReader : public DataSource {
 public:
  explicit GfsReader(const std::string& path);
  ~GfsReader() override;
  bool next(Measurement& out) override;
  double progress() const override;
  std::string format() const override;

  // True when the head of a file looks like a GMapping gfs log.
  static bool sniff(const std::string& first_bytes);

 private:
  bool parseLine(const std::string& line);
  void emitOdometry(double t, const common::Pose2& pose);

  std::unique_ptr<detail::TextScanner> text_;
  std::vector<std::string> fields_;
  std::vector<Measurement> pending_;
  size_t pending_pos_ = 0;
  double max_range_m_ = 80;  // PARAM maxrange; GMapping writes no-returns as 81.91
  bool have_held_ = false;   // an ODOM line's time waits for its pose (the next ODOM line)
  double held_time_ = 0;
  bool any_odometry_ = false;
  double last_odometry_time_ = 0;
};

}  // namespace urbanslam::io
