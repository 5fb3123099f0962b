#pragma once
// The 20 rotation-invariant scalar features of a laser scan (thesis §3.2.1, eqs 3.6–3.24), followed
// by the shape descriptors of ShapeFeatures.h. Each is a pure function of one scan and the gates
// r_max, g_max_dist and g_min_size; a loop closure is then decided from comparisons of two scans'
// features (Comparisons.h, WeakClassifier.h).
//
// Conventions shared by all features (the thesis leaves them implicit):
//  * A beam is "short" when it is a real return with r < r_max. No-return beams count as
//    r >= r_max (they are beams that saw nothing within r_max).
//  * Where a feature needs a point for a far beam (area 3.6, far distance 3.16, the clamped
//    centroid), its range is clamped to r_max, as eq. 3.6 does.
//  * Consecutive-beam features (3.6, 3.11, 3.14–3.16, groups, 3.19, 3.21) use pairs (i, i+1);
//    a scan covering 360° also uses the wrap-around pair (N-1, 0), so that rotating the sensor
//    (a cyclic shift of the beams) leaves every feature unchanged. A pair/triple is used only
//    when all its points are short (3.11, 3.14, 3.15, 3.19, 3.21 exclude far points).
//  * N in the divisors of 3.7, 3.8 and 3.20 is the number of beams, as printed in the thesis.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "urbanslam/io/LaserScan.h"
#include "urbanslam/laser_loop/ShapeFeatures.h"

namespace urbanslam::laser_loop {

struct FeatureParams {
  double r_max_m = 50.0;      // ranges at or beyond this count as far (no structure seen)
  double g_max_dist_m = 1.0;  // gate on the distance between consecutive points (3.11, groups)
  int g_min_size = 3;         // a cluster is a group when it has more than this many points
  // Counts and sums over beams (size, distances, groups, angular difference, ...) scale with the
  // angular resolution, so features of a 0.5° SICK and a 1° SICK are not comparable. Scans finer
  // than this are decimated to it (every k-th beam, k = round(this / increment)) before the
  // features are computed; 0 keeps every beam.
  double beam_increment_deg = 1.0;
  // Each feature f is replaced by sign(f)·ln(1 + |f|) after it is computed. The weak classifiers
  // of 3.25 then threshold |Δ ln(1 + f)|, i.e. roughly the ratio of two scans' values rather than
  // their difference, so a threshold learned in small indoor rooms still means "alike" in a large
  // outdoor place. Measured on held-out logs (share/laser_loop/README.md): detection at 1 % FA
  // indoor → campus 34 % → 44 %, but Victoria Park (sparse tree scans, few returns) 35 % → 18 %,
  // so it is off by default. Still a pure, rotation-invariant function of one scan. Off
  // reproduces the thesis's features exactly.
  bool log_features = false;
};

enum class Feature : int {
  Area = 0,               // 3.6
  AverageRange,           // 3.7
  MeanCentroid,           // 3.8–3.9 (short points, divided by N)
  ClampedCentroid,        // the twentieth: centroid of all beams with ranges clamped to r_max
  CloseArea,              // 3.10
  CloseDistance,          // 3.11
  CircularityResidual,    // 3.12–3.13: algebraic residual sum of squares [m^4]
  CircularityRadius,      // 3.12–3.13: radius of the least-squares circle [m]
  CurvatureMean,          // 3.14
  CurvatureStd,           // 3.14
  Distance,               // 3.15
  FarDistance,            // 3.16
  GroupCount,             // groups
  GroupMeanSize,          // groups
  MaxRangeCount,          // 3.17–3.18
  MeanAngularDifference,  // 3.19 (a sum, as the equation says)
  MeanDeviation,          // 3.20
  Regularity,             // 3.21
  Size,                   // 3.22–3.23
  StdRange,               // 3.24
};
constexpr int kThesisFeatureCount = 20;
// The thesis's twenty, then the shape descriptors of ShapeFeatures.h (index kThesisFeatureCount + i).
constexpr int kFeatureCount = kThesisFeatureCount + kShapeFeatureCount;

using FeatureVector = std::array<double, kFeatureCount>;

// Stable names used in model files and CSV headers ("area", "average_range", ..., "extent_major", ...).
const char* featureName(Feature f);
inline const char* featureName(int i) { return featureName(static_cast<Feature>(i)); }
// Index of a feature name; -1 when unknown.
int featureIndex(const std::string& name);

// A scan as polar beams: range (no-return beams marked by valid = 0) and bearing. Bearings must
// be increasing; `closed` says the beams cover the full circle (the last beam neighbours the
// first); angle_increment_rad is δα of eq. 3.10.
struct PolarScan {
  std::vector<double> ranges;
  std::vector<double> bearings;
  std::vector<uint8_t> valid;
  double angle_increment_rad = 0;
  bool closed = false;
};

// From a LaserScan in the sensor frame. A scan is closed when N · increment reaches 360°.
PolarScan toPolar(const io::LaserScan& scan);
// Whether the scan's beams cover the full circle (N · increment within half a beam of 360°).
bool coversFullCircle(const io::LaserScan& scan);

// Several lasers of one vehicle (e.g. front + back) merged into one polar scan about the vehicle
// origin: every return is moved into the vehicle frame, re-expressed as (range, bearing) and the
// beams sorted by bearing. The merged scan is closed when the bearings cover the full circle
// without a gap larger than 4 beam increments. Each scan finer than beam_increment_deg (> 0) is
// decimated first, as computeFeatures(LaserScan) does.
PolarScan mergeScans(const std::vector<io::LaserScan>& scans, double beam_increment_deg = 0);

FeatureVector computeFeatures(const PolarScan& scan, const FeatureParams& params);
FeatureVector computeFeatures(const io::LaserScan& scan, const FeatureParams& params);

}  // namespace urbanslam::laser_loop
