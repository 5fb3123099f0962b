#pragma once
// Rotation-invariant shape descriptors of a scan, beyond the thesis's twenty scalars. The twenty
// summarise a scan in single numbers (mean range, area, ...), which along a city street are the
// same at every position: on a held-out simulated city with a 360° laser they detect about half
// of the revisits at 1 % false alarm. These keep the distributions instead:
//  * the clamped ranges' distribution: a histogram (fraction of beams per bin of r_max / 20) and
//    its 5 %, 10 %, ..., 95 % quantiles (the quantiles' L1 difference is the Wasserstein distance
//    between two scans' range distributions, Comparisons.h);
//  * the short points' spread along their principal axes, taken about the sensor: the two
//    extents (square roots of the second-moment matrix's eigenvalues) and the 10 %, ..., 90 %
//    quantiles of |along| and |across| — in a street, the distances to the facades on either
//    side and how far the street runs, which change with the place and not with the heading.
// Each is invariant to rotating the sensor (a cyclic shift of a closed scan's beams; the axes
// turn with the points, and |·| removes their sign) and to the beams' order.
#include <cstddef>
#include <cstdint>

namespace urbanslam::laser_loop {

constexpr int kAxisQuantiles = 9;    // 10 %, 20 %, ..., 90 %
constexpr int kHistogramBins = 20;   // bins of r_max / 20; far beams fall in the last
constexpr int kRangeQuantiles = 19;  // 5 %, 10 %, ..., 95 %
constexpr int kShapeExtents = 0;     // offsets within the shape block
constexpr int kShapeAlong = 2;
constexpr int kShapeAcross = kShapeAlong + kAxisQuantiles;
constexpr int kShapeHistogram = kShapeAcross + kAxisQuantiles;
constexpr int kShapeQuantiles = kShapeHistogram + kHistogramBins;
constexpr int kShapeFeatureCount = kShapeQuantiles + kRangeQuantiles;

// From the n beams of a scan: clamped ranges r (far beams at r_max), the points (x, y) of the
// beams in the sensor frame and which beams are short (a real return below r_max). Writes
// kShapeFeatureCount values to out. Zeros where there is no short point.
void computeShapeFeatures(const double* r, const double* x, const double* y, const uint8_t* is_short, size_t n, double r_max, double* out);

// Stable names ("extent_major", "along_q10", "range_hist_00", "range_q05", ...).
const char* shapeFeatureName(int i);

}  // namespace urbanslam::laser_loop
