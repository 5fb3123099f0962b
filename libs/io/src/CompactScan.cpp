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

void CompactScan::write(common::BinaryWriter& w) const {
  w.f64(timestamp_);
  w.string(label_);
  w.f64(angle_min_rad_);
  w.f64(angle_increment_rad_);
  w.f64(max_range_m_);
  w.f64(sensor_pose_.x);
  w.f64(sensor_pose_.y);
  w.f64(sensor_pose_.phi);
  w.f64(step_m_);
  w.f32(far_m_);
  w.u32(beams_);
  w.size(data_.size());
  for (const std::uint16_t v : data_) {
    w.u8(static_cast<std::uint8_t>(v & 0xFF));
    w.u8(static_cast<std::uint8_t>(v >> 8));
  }
}

CompactScan CompactScan::read(common::BinaryReader& r) {
  CompactScan s;
  s.timestamp_ = r.f64();
  s.label_ = r.string();
  s.angle_min_rad_ = r.f64();
  s.angle_increment_rad_ = r.f64();
  s.max_range_m_ = r.f64();
  s.sensor_pose_.x = r.f64();
  s.sensor_pose_.y = r.f64();
  s.sensor_pose_.phi = r.f64();
  s.step_m_ = r.f64();
  s.far_m_ = r.f32();
  s.beams_ = r.u32();
  const size_t words = r.count(2);
  if (words != s.beams_ + flagWords(s.beams_)) r.fail("a compact scan's codes do not match its beam count");
  s.data_.resize(words);
  for (auto& v : s.data_) {
    const std::uint16_t lo = r.u8();
    v = static_cast<std::uint16_t>(lo | static_cast<std::uint16_t>(r.u8()) << 8);
  }
  return s;
}

LaserScan CompactScan::expand() const {
  LaserScan s;
  expandInto(s);
  return s;
}

}  // namespace urbanslam::io
