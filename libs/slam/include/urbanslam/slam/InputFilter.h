#pragma once
// Which laser scans a job reads and which of their beams it trusts ([input] options): the
// sensor labels to use and the range limits. Mapping and localization read a log the same way,
// so a map's scans and the scans localized in it are comparable.
#include <string>
#include <vector>

#include "urbanslam/io/LaserScan.h"
#include "urbanslam/slam/PipelineOptions.h"

namespace urbanslam::slam {

class InputFilter {
 public:
  explicit InputFilter(const InputOptions& options);
  // Whether scans of this sensor are used (every sensor when no labels are configured).
  bool accepts(const std::string& label) const;
  // Marks the beams outside [min_range_m, max_range_m) as no-returns.
  void limitRanges(io::LaserScan& scan) const;

 private:
  std::vector<std::string> labels_;
  double min_range_m_, max_range_m_;
};

}  // namespace urbanslam::slam
