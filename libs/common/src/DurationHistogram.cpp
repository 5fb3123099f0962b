#include "urbanslam/common/DurationHistogram.h"

#include <algorithm>
#include <cmath>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::common {

namespace {

constexpr double kSmallestMs = 1e-3;  // the first bin's lower edge
constexpr double kGrowth = 1.01;      // each bin's upper edge over its lower edge
constexpr size_t kBins = 2316;        // up to kSmallestMs * kGrowth^kBins, about 10⁷ ms
const double kLogGrowth = std::log(kGrowth);

size_t binOf(double ms) {
  if (!(ms > kSmallestMs)) return 0;  // also NaN
  const double b = std::floor(std::log(ms / kSmallestMs) / kLogGrowth);
  return std::min(kBins - 1, static_cast<size_t>(b));
}

double centreOf(size_t bin) { return kSmallestMs * std::exp((static_cast<double>(bin) + 0.5) * kLogGrowth); }

}  // namespace

void DurationHistogram::add(double ms) {
  const size_t b = binOf(ms);
  if (b >= bins_.size()) bins_.resize(b + 1, 0);
  ++bins_[b];
  max_ = count_ == 0 ? ms : std::max(max_, ms);
  ++count_;
}

double DurationHistogram::orderStatistic(size_t i) const {
  size_t seen = 0;
  for (size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (i < seen) return std::min(centreOf(b), max_);
  }
  return max_;
}

double DurationHistogram::percentile(double p) const {
  if (count_ == 0) return 0.0;
  const double pos = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(count_ - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  if (lo + 1 >= count_) return max_;
  const double f = pos - static_cast<double>(lo);
  const double a = orderStatistic(lo);
  return f == 0 ? a : a + f * (orderStatistic(lo + 1) - a);
}

void DurationHistogram::write(BinaryWriter& w) const {
  w.size(count_);
  w.f64(max_);
  w.size(bins_.size());
  for (std::uint64_t n : bins_) w.u64(n);
}

void DurationHistogram::read(BinaryReader& r) {
  const size_t count = r.size();
  const double max = r.f64();
  std::vector<std::uint64_t> bins(r.count(8));
  if (bins.size() > kBins)
    throw InputError("a duration histogram with " + std::to_string(bins.size()) + " bins (at most " + std::to_string(kBins) + ")");
  std::uint64_t total = 0;
  for (auto& n : bins) {
    n = r.u64();
    if (n > count - total) throw InputError("a duration histogram whose bins hold more durations than its count, " + std::to_string(count));
    total += n;
  }
  if (total != count)
    throw InputError("a duration histogram whose bins hold " + std::to_string(total) + " durations, not " + std::to_string(count));
  bins_ = std::move(bins);
  count_ = count;
  max_ = max;
}

}  // namespace urbanslam::common
