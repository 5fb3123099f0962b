#include "urbanslam/io/CompactScan.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace urbanslam::io {

namespace {
constexpr std::uint16_t kNotFinite = 0xFFFF;
constexpr std::uint16_t kFar = 0xFFFE;
constexpr double kLargestCode = 0xFFFD;
constexpr double kMinStepM = 0.001;
constexpr size_t kFlagBits = 16;

size_t flagWords(size_t beams) { return (beams + kFlagBits - 1) / kFlagBits; }
}  // namespace

CompactScan::CompactScan(const LaserScan& scan)
    : timestamp_(scan.timestamp),
      label_(scan.label),
      angle_min_rad_(scan.angle_min_rad),
      angle_increment_rad_(scan.angle_increment_rad),
      max_range_m_(scan.max_range_m),
      sensor_pose_(scan.sensor_pose),
      beams_(static_cast<std::uint32_t>(scan.ranges.size())) {
  const size_t n = scan.ranges.size();
  // The step reaches every valid return. With 1 mm (returns within 65 m) the ranges of a log
  // written in millimetres or centimetres come back as the same floats.
  double reach = 0;
  for (size_t i = 0; i < n; ++i)
    if (i < scan.valid.size() && scan.valid[i] && std::isfinite(scan.ranges[i]))
      reach = std::max(reach, static_cast<double>(scan.ranges[i]));
  step_m_ = std::max(kMinStepM, reach / kLargestCode);
  data_.assign(n + flagWords(n), 0);
  for (size_t i = 0; i < n; ++i) {
    const float r = scan.ranges[i];
    const double q = std::round(static_cast<double>(r) / step_m_);
    if (!std::isfinite(r)) {
      data_[i] = kNotFinite;
    } else if (q > kLargestCode) {
      // An invalid beam beyond the step's reach (a no-return at the scanner's maximum, or
      // beyond it): all such come back as the longest of them, still at or beyond the maximum.
      data_[i] = kFar;
      far_m_ = std::max(far_m_, r);
    } else {
      data_[i] = static_cast<std::uint16_t>(std::max(0.0, q));
    }
    if (i < scan.valid.size() && scan.valid[i]) data_[n + i / kFlagBits] |= static_cast<std::uint16_t>(1u << (i % kFlagBits));
  }
  data_.shrink_to_fit();
}

void CompactScan::expandInto(LaserScan& out) const {
  out.timestamp = timestamp_;
  out.label = label_;
  out.angle_min_rad = angle_min_rad_;
  out.angle_increment_rad = angle_increment_rad_;
  out.max_range_m = max_range_m_;
  out.sensor_pose = sensor_pose_;
  const size_t n = beams_;
  out.ranges.resize(n);
  out.valid.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const std::uint16_t c = data_[i];
    out.ranges[i] = c == kNotFinite ? std::numeric_limits<float>::infinity() : c == kFar ? far_m_ : static_cast<float>(c * step_m_);
    out.valid[i] = (data_[n + i / kFlagBits] >> (i % kFlagBits)) & 1u;
  }
}

size_t CompactScan::validCount() const {
  size_t n = 0;
  for (size_t w = beams_; w < data_.size(); ++w) n += static_cast<size_t>(__builtin_popcount(data_[w]));
  return n;
}

LaserScan CompactScan::expand() const {
  LaserScan s;
  expandInto(s);
  return s;
}

}  // namespace urbanslam::io
