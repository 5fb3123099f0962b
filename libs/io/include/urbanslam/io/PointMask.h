#pragma once
// Which of a map's points its clouds keep: one flag per point, in the order the cloud writers
// visit them (each scan's valid beams in order, scan after scan, before any decimation). A bit
// a point, so a city's mask is a few megabytes where its points would be gigabytes.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace urbanslam::io {

class PointMask {
 public:
  void push(bool keep) {
    if (size_ % 64 == 0) bits_.push_back(0);
    if (keep) {
      bits_.back() |= uint64_t{1} << (size_ % 64);
      ++kept_;
    }
    ++size_;
  }
  // Points past the end are kept: a mask covers the points it was computed for.
  bool keeps(size_t point) const { return point >= size_ || ((bits_[point / 64] >> (point % 64)) & 1u) != 0; }
  size_t size() const { return size_; }
  size_t kept() const { return kept_; }

 private:
  std::vector<uint64_t> bits_;
  size_t size_ = 0, kept_ = 0;
};

}  // namespace urbanslam::io
