#include "urbanslam/slam/TrackingMonitor.h"

#include <algorithm>

#include "urbanslam/esdf/Gating.h"

namespace urbanslam::slam {

TrackingMonitor::TrackingMonitor(TrackingMonitorOptions options)
    : options_(options), cap_(esdf::chi2Quantile(options.probability, 3)) {
  options_.window_scans = std::max(1, options_.window_scans);
  thresholds_.push_back(0.0);
  for (int k = 1; k <= options_.window_scans; ++k) thresholds_.push_back(esdf::chi2Quantile(options_.probability, 3 * k));
}

void TrackingMonitor::reset() { window_.clear(); }

void TrackingMonitor::push(Entry e) {
  window_.push_back(e);
  while (window_.size() > static_cast<size_t>(options_.window_scans)) window_.pop_front();
}

void TrackingMonitor::addMatch(double mahalanobis2) { push({true, std::min(std::max(0.0, mahalanobis2), cap_)}); }

void TrackingMonitor::addFailure() { push({false, 0.0}); }

double TrackingMonitor::windowSum() const {
  double s = 0;
  for (const Entry& e : window_) s += e.term;
  return s;
}

double TrackingMonitor::windowThreshold() const {
  int matched = 0;
  for (const Entry& e : window_) matched += e.matched ? 1 : 0;
  return thresholds_[static_cast<size_t>(matched)];
}

bool TrackingMonitor::lost() const {
  int failed = 0;
  for (const Entry& e : window_) failed += e.matched ? 0 : 1;
  if (2 * failed > options_.window_scans) return true;
  return static_cast<int>(window_.size()) > failed && windowSum() > windowThreshold();
}

}  // namespace urbanslam::slam
