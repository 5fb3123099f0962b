#pragma once
// CARMEN logs read directly, keeping their timestamps (MRPT's carmen2rawlog loses them and
// gives 180-beam logs a 90° field of view). Lines that share one printed time are spread over
// the step that time stands for (see CarmenReader::next).
//
// Freiburg "corrected" logs hold GMapping's corrected pose in FLASER and re-anchor ODOM at each
// corrected scan pose (the ODOM line right after a FLASER repeats its pose). Raw odometry is
// rebuilt by chaining the increments between consecutive ODOM lines inside each segment and
// skipping the jump to each anchor; the corrected FLASER poses come out as ReferencePose.
#include <string>
#include <vector>

#include "urbanslam/io/DataSource.h"

namespace urbanslam::io {

namespace detail {
class TextScanner;
}

struct CarmenInfo {
  bool corrected = false;      // Freiburg corrected log: FLASER poses are a reference trajectory
  bool has_timestamps = true;  // false: timestamps all 0 or mostly repeated; scan index used instead
  double front_max_range_m = 80;
  double rear_max_range_m = 80;
  double front_offset_m = 0, rear_offset_m = 0;
};

class CarmenReader : public DataSource {
 public:
  explicit CarmenReader(const std::string& path);
  ~CarmenReader() override;
  bool next(Measurement& out) override;
  double progress() const override;
  std::string format() const override;
  const CarmenInfo& info() const { return info_; }

  // True when the first lines look like a CARMEN log.
  static bool sniff(const std::string& first_bytes);

 private:
  void prescan();
  bool parseLine(const std::string& line);
  void handleOdom(const std::vector<std::string>& f, const std::string& where);
  void handleLaser(const std::vector<std::string>& f, const std::string& where, bool rear);
  void handleRobotLaser(const std::vector<std::string>& f, const std::string& where);
  void handleParam(const std::vector<std::string>& f);
  double stamp(double log_ts, bool is_scan);
  double lineStamp(const std::string& token, const std::string& where, bool is_scan);
  void releaseRun();
  void noteStampFormat(const std::string& token);
  void emitScan(LaserScan scan, const common::Pose2& log_pose, const common::Pose2& odom_pose);

  CarmenInfo info_;
  std::unique_ptr<detail::TextScanner> text_;
  std::vector<Measurement> pending_;  // what the current line yields (a line can yield several)
  // Lines sharing one printed time, held until the time changes (see next()).
  static constexpr size_t kMaxRunLines = 4096;  // bounds memory on logs whose time never moves
  std::vector<std::vector<Measurement>> run_;
  double run_stamp_ = 0, run_step_ = 0;
  double line_step_ = 0;       // printed resolution of the current line's time
  bool line_is_scan_ = false;  // the current line is a laser line
  // How the log prints its times (prescan): fixed-point keeps trailing zeros, %g does not.
  bool stamp_fixed_point_ = false;
  int stamp_digits_ = 0;            // most significant digits seen
  std::vector<Measurement> ready_;  // released measurements, handed out in order
  size_t ready_pos_ = 0;
  std::vector<std::string> fields_;

  // Raw odometry reconstruction.
  bool have_odom_ = false;  // an ODOM line was seen
  bool have_raw_ = false;
  common::Pose2 last_odom_line_;  // pose of the previous ODOM line (its segment's frame)
  common::Pose2 raw_;             // chained raw odometry
  bool last_was_scan_ = false;    // the previous record was a FLASER/RLASER/ROBOTLASER1
  common::Pose2 last_scan_pose_;  // its logged pose (an anchor repeats it)
  long scans_ = 0;
  bool any_odom_lines_ = false;  // from the prescan: ODOM lines exist
};

}  // namespace urbanslam::io
