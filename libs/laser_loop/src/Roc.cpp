#include "urbanslam/laser_loop/Roc.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace urbanslam::laser_loop {

Roc::Roc(std::vector<double> p, std::vector<double> n) : pos_(std::move(p)), neg_(std::move(n)) {
  std::sort(pos_.begin(), pos_.end(), std::greater<>());
  std::sort(neg_.begin(), neg_.end(), std::greater<>());
}

OperatingPoint Roc::at(double fa) const {
  OperatingPoint op;
  op.target_false_alarm = fa;
  if (pos_.empty()) return op;
  // k false alarms are allowed; the threshold must lie strictly above the (k+1)-th highest
  // negative score, and as low as that allows.
  const size_t k = static_cast<size_t>(std::floor(fa * static_cast<double>(neg_.size()) + 1e-9));
  if (k >= neg_.size()) {
    op.detection = 1.0;
    op.false_alarm = neg_.empty() ? 0.0 : 1.0;
    op.threshold = pos_.back();
    return op;
  }
  const double bar = neg_[k];
  const size_t detected =
      static_cast<size_t>(std::lower_bound(pos_.begin(), pos_.end(), bar, [](double a, double b) { return a > b; }) - pos_.begin());
  op.detection = static_cast<double>(detected) / static_cast<double>(pos_.size());
  op.false_alarm = static_cast<double>(k) / static_cast<double>(neg_.size());
  op.threshold = std::nextafter(bar, std::numeric_limits<double>::infinity());
  // The actual false alarms at that threshold are the negatives strictly above bar (≤ k).
  const size_t fas =
      static_cast<size_t>(std::lower_bound(neg_.begin(), neg_.end(), bar, [](double a, double b) { return a > b; }) - neg_.begin());
  op.false_alarm = static_cast<double>(fas) / static_cast<double>(neg_.size());
  return op;
}

std::vector<RocPoint> Roc::curve(size_t max_points) const {
  std::vector<double> thr;
  thr.reserve(pos_.size() + neg_.size());
  thr.insert(thr.end(), pos_.begin(), pos_.end());
  thr.insert(thr.end(), neg_.begin(), neg_.end());
  std::sort(thr.begin(), thr.end(), std::greater<>());
  thr.erase(std::unique(thr.begin(), thr.end()), thr.end());
  std::vector<RocPoint> out;
  out.push_back({std::numeric_limits<double>::infinity(), 0.0, 0.0});
  size_t ip = 0, in = 0;
  for (double t : thr) {
    while (ip < pos_.size() && pos_[ip] >= t) ++ip;
    while (in < neg_.size() && neg_[in] >= t) ++in;
    out.push_back({t, neg_.empty() ? 0.0 : double(in) / double(neg_.size()), pos_.empty() ? 0.0 : double(ip) / double(pos_.size())});
  }
  if (out.size() > max_points && max_points >= 2) {
    std::vector<RocPoint> thin;
    for (size_t i = 0; i < max_points; ++i) thin.push_back(out[i * (out.size() - 1) / (max_points - 1)]);
    return thin;
  }
  return out;
}

double Roc::auc() const {
  const auto c = curve(std::numeric_limits<size_t>::max());
  double a = 0;
  for (size_t i = 1; i < c.size(); ++i) a += (c[i].false_alarm - c[i - 1].false_alarm) * 0.5 * (c[i].detection + c[i - 1].detection);
  return a;
}

}  // namespace urbanslam::laser_loop
