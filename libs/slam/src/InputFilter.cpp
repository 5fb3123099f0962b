#include "urbanslam/slam/InputFilter.h"

#include <sstream>

namespace urbanslam::slam {

InputFilter::InputFilter(const InputOptions& options) : min_range_m_(options.min_range_m), max_range_m_(options.max_range_m) {
  std::stringstream ss(options.laser_labels);
  std::string label;
  while (std::getline(ss, label, ',')) {
    label.erase(0, label.find_first_not_of(" \t"));
    label.erase(label.find_last_not_of(" \t") + 1);
    if (!label.empty()) labels_.push_back(label);
  }
}

bool InputFilter::accepts(const std::string& label) const {
  if (labels_.empty()) return true;
  for (const auto& l : labels_)
    if (l == label) return true;
  return false;
}

void InputFilter::limitRanges(io::LaserScan& scan) const {
  const double lo = min_range_m_, hi = max_range_m_;
  if (lo <= 0 && hi <= 0) return;
  for (size_t i = 0; i < scan.ranges.size(); ++i)
    if (scan.ranges[i] < lo || (hi > 0 && scan.ranges[i] >= hi)) scan.valid[i] = 0;
}

}  // namespace urbanslam::slam
