#include "urbanslam/laser_loop/ShapeFeatures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace urbanslam::laser_loop {

namespace {

// Element floor(f · size) of a sorted vector: the same rule for every quantile here.
double quantile(const std::vector<double>& sorted, int k, int parts) {
  const size_t i = static_cast<size_t>(k) * sorted.size() / static_cast<size_t>(parts);
  return sorted[std::min(i, sorted.size() - 1)];
}

std::array<std::string, kShapeFeatureCount> makeNames() {
  std::array<std::string, kShapeFeatureCount> n;
  n[kShapeExtents] = "extent_major";
  n[kShapeExtents + 1] = "extent_minor";
  auto two = [](int v) { return (v < 10 ? "0" : "") + std::to_string(v); };
  for (int k = 0; k < kAxisQuantiles; ++k) {
    n[kShapeAlong + k] = "along_q" + std::to_string(10 * (k + 1));
    n[kShapeAcross + k] = "across_q" + std::to_string(10 * (k + 1));
  }
  for (int k = 0; k < kHistogramBins; ++k) n[kShapeHistogram + k] = "range_hist_" + two(k);
  for (int k = 0; k < kRangeQuantiles; ++k) n[kShapeQuantiles + k] = "range_q" + two(5 * (k + 1));
  return n;
}

}  // namespace

const char* shapeFeatureName(int i) {
  static const auto names = makeNames();
  return i >= 0 && i < kShapeFeatureCount ? names[static_cast<size_t>(i)].c_str() : "?";
}

void computeShapeFeatures(const double* r, const double* x, const double* y, const uint8_t* is_short, size_t n, double r_max, double* out) {
  std::fill(out, out + kShapeFeatureCount, 0.0);
  if (n == 0) return;
  thread_local std::vector<double> sorted, along, across;
  sorted.assign(r, r + n);
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < kRangeQuantiles; ++k) out[kShapeQuantiles + k] = quantile(sorted, k + 1, kRangeQuantiles + 1);
  const double bin = r_max / kHistogramBins;
  for (size_t i = 0; i < n; ++i) out[kShapeHistogram + std::min(kHistogramBins - 1, static_cast<int>(r[i] / bin))] += 1.0;
  for (int k = 0; k < kHistogramBins; ++k) out[kShapeHistogram + k] /= static_cast<double>(n);

  // Second moments about the sensor, not the centroid: the sensor's place among the points (the
  // middle of a street, near one facade) is what tells two positions apart.
  double sxx = 0, syy = 0, sxy = 0;
  size_t m = 0;
  for (size_t i = 0; i < n; ++i)
    if (is_short[i]) {
      sxx += x[i] * x[i];
      syy += y[i] * y[i];
      sxy += x[i] * y[i];
      ++m;
    }
  if (m == 0) return;
  sxx /= static_cast<double>(m);
  syy /= static_cast<double>(m);
  sxy /= static_cast<double>(m);
  const double half_trace = 0.5 * (sxx + syy);
  const double disc = std::sqrt(std::max(0.0, 0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy));
  out[kShapeExtents] = std::sqrt(half_trace + disc);
  out[kShapeExtents + 1] = std::sqrt(std::max(0.0, half_trace - disc));
  const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
  const double c = std::cos(theta), s = std::sin(theta);
  along.clear();
  across.clear();
  for (size_t i = 0; i < n; ++i)
    if (is_short[i]) {
      along.push_back(std::fabs(c * x[i] + s * y[i]));
      across.push_back(std::fabs(-s * x[i] + c * y[i]));
    }
  std::sort(along.begin(), along.end());
  std::sort(across.begin(), across.end());
  for (int k = 0; k < kAxisQuantiles; ++k) {
    out[kShapeAlong + k] = quantile(along, k + 1, kAxisQuantiles + 1);
    out[kShapeAcross + k] = quantile(across, k + 1, kAxisQuantiles + 1);
  }
}

}  // namespace urbanslam::laser_loop
