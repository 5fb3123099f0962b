#pragma once
// A laser scan as a map keeps it for the whole run: every range as a 16-bit multiple of a
// per-scan step and the validity flags as bits, about 2.1 bytes a beam against 5 for a
// LaserScan (a 361-beam scan: some 800 bytes instead of 1.8 KB). The scan is expanded into a
// LaserScan whenever one is needed (alignment, outputs); nothing keeps the expanded form.
//
// The step is max(1 mm, R / 65533) where R is the longest finite valid range, so every valid
// range is kept within half a step, and exactly when the log has millimetres and R < 65 m.
// Invalid beams keep their ranges too (quantised the same way; those beyond the step's reach,
// the no-returns at the scanner's maximum, all come back as the longest of them): the
// free-space test reads them to tell a no-return from a reading filtered out. Non-finite
// ranges come back as +infinity, negative ones as 0.
#include <cstdint>
#include <string>
#include <vector>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"

namespace urbanslam::io {

class CompactScan {
 public:
  CompactScan() = default;
  explicit CompactScan(const LaserScan& scan);

  // The scan as a LaserScan (ranges within step_m() / 2 of the original).
  LaserScan expand() const;
  // The same into `out`, reusing its buffers (one scan after another without reallocating).
  void expandInto(LaserScan& out) const;

  size_t size() const { return beams_; }
  bool empty() const { return beams_ == 0; }
  double timestamp() const { return timestamp_; }
  double stepM() const { return step_m_; }
  // Beams flagged valid (the expanded scan's validCount(), without expanding it).
  size_t validCount() const;
  // Memory it takes, its buffers included.
  size_t memoryBytes() const { return sizeof(*this) + label_.capacity() + data_.capacity() * sizeof(std::uint16_t); }

  // Exactly as held (codes, not ranges): read gives back an equal scan. Not a file format for
  // users (a map file writes scans expanded); the scan store's spill file.
  void write(common::BinaryWriter& w) const;
  static CompactScan read(common::BinaryReader& r);

 private:
  double timestamp_ = 0;
  std::string label_;
  double angle_min_rad_ = 0;
  double angle_increment_rad_ = 0;
  double max_range_m_ = 0;
  common::Pose2 sensor_pose_;
  double step_m_ = 0;
  float far_m_ = 0;  // what the invalid ranges beyond the step's reach come back as
  std::uint32_t beams_ = 0;
  // beams_ range codes, then the validity flags, 16 to a word (one allocation for both). Code
  // kNotFinite stands for a NaN or infinite range.
  std::vector<std::uint16_t> data_;
};

}  // namespace urbanslam::io
