#pragma once
// Durations summarised in constant memory, for the percentiles of stats.json: counts in bins one
// per cent wide relative to their value (1 µs to about 10⁷ ms; the first and last bins also
// count what lies beyond), so a percentile is within one per cent of the sample's however long
// the run, and the maximum is exact. A run of 10⁶ keyframes took 16 bytes per step to keep
// every duration (and as much again in map.usmap); this takes at most 19 KB per histogram.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace urbanslam::common {

class BinaryWriter;
class BinaryReader;

class DurationHistogram {
 public:
  void add(double ms);
  size_t count() const { return count_; }
  bool empty() const { return count_ == 0; }
  double max() const { return max_; }
  // Percentile p in [0, 100] as common::percentile takes it (linear between the order
  // statistics), each order statistic read as the geometric centre of its bin; 100 is the exact
  // maximum, an empty histogram gives 0.
  double percentile(double p) const;

  void write(BinaryWriter& w) const;
  // Throws common::InputError (through the reader) for a histogram that cannot be one.
  void read(BinaryReader& r);

 private:
  // The i-th order statistic (0-based) as its bin's centre.
  double orderStatistic(size_t i) const;
  std::vector<std::uint64_t> bins_;  // up to the largest bin used
  size_t count_ = 0;
  double max_ = 0;
};

}  // namespace urbanslam::common
