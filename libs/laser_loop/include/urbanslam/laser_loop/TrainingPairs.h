#pragma once
// Labelled scan pairs from real logs. Every scan of a log gets its features and a
// reference position; two scans of the same log form a positive pair when they were taken within
// d_pos of each other (any heading) and a negative pair when farther apart than d_neg; pairs in
// between are ambiguous and never used.
//
// Reference positions come from, in order of preference:
//  * ReferencePose records (Freiburg corrected CARMEN logs: the corrected FLASER pose, same
//    timestamp as its scan; MRPT rawlogs with REFERENCE poses), matched to the scan nearest in
//    time within ref_max_gap_s;
//  * GPS fixes (Victoria Park): the position linearly interpolated between the fixes just before
//    and after the scan when both are within gps_max_gap_s of it (the heading is the direction
//    between those fixes when they are ≥ 0.5 m apart). Victoria Park's GPS jumps by metres at
//    times (ACFR's own warning), so those labels are noisier than the corrected logs'.
// Scans with neither are dropped (counted). Scans of different lasers with the same timestamp
// (front + rear) are merged into one (mergeScans) before their features are computed.
//
// A positive pair must also be a revisit: the reference trajectory between the two scans must be
// at least min_travel_m long. Otherwise consecutive scans of a slowly moving robot — the same
// place seen a second later from the same heading — would dominate the positives and measure
// nothing about loop closure.
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/laser_loop/ScanFeatures.h"
#include "urbanslam/laser_loop/WeakClassifier.h"

namespace urbanslam::laser_loop {

struct LabelledScan {
  FeatureVector features{};
  common::Pose2 pose;  // reference pose (x, y; phi valid when has_heading)
  bool has_heading = true;
  double timestamp = 0;
  double path_m = 0;  // length of the reference trajectory from the first labelled scan
};

struct ScanLoadOptions {
  FeatureParams params;
  double ref_max_gap_s = 0.05;
  double gps_max_gap_s = 1.0;
  // > 0: each scan's features are those of the virtual 360° scan built from the scans of the last
  // this many metres of odometry (SubmapScan.h); the log must carry odometry. 0: the scan alone.
  double submap_window_m = 0;
  // Optional: called with the fraction of the input read.
  std::function<void(double)> progress;
};

struct ScanSet {
  std::string source;          // path
  std::string format;          // DataSource::format()
  std::string reference_kind;  // "reference poses" or "GPS (interpolated, ≤ 1 s)"
  std::vector<LabelledScan> scans;
  size_t scans_read = 0;
  size_t scans_without_reference = 0;
};

// Reads a whole log (any format io::openDataSource accepts). Throws common::InputError when the
// log carries no reference trajectory at all.
ScanSet loadLabelledScans(const std::string& path, const ScanLoadOptions& options);

struct PairRules {
  double d_pos_m = 1.0;
  double d_neg_m = 3.0;
  double min_travel_m = 10.0;
  // Positives only up to this heading difference (π: any heading, the definition). A
  // 180° scanner sees disjoint halves of a place from opposite headings, so restricting it
  // measures the classifier on pairs whose scans can overlap. Scans without a heading pass.
  double max_heading_diff_rad = M_PI;
  size_t max_positives = 20000;         // random subset when more exist
  double negatives_per_positive = 1.0;  // 1 = balanced (training); more for FA resolution (eval)
  size_t min_negatives = 0;             // at least this many negatives (when available)
  uint64_t seed = 1;
};

struct LabelledPair {
  uint32_t set = 0;  // index of the ScanSet
  uint32_t a = 0, b = 0;
  bool match = false;
  double distance_m = 0;
  double heading_diff_rad = -1;  // |Δφ| in [0, π]; −1 when a heading is unknown
};

// All revisit positives (subsampled to max_positives) and randomly drawn negatives, in a random
// order. Deterministic for a given seed.
std::vector<LabelledPair> samplePairs(const ScanSet& set, uint32_t set_index, const PairRules& rules);

// The comparison table for AdaBoost (row i = pairs[i]), its first `comparisons` columns.
PairTable makePairTable(const std::vector<ScanSet>& sets, const std::vector<LabelledPair>& pairs, int comparisons = kComparisonCount);

}  // namespace urbanslam::laser_loop
