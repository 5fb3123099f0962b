#pragma once
// The trained laser loop-closure classifier on disk: a small versioned text file that a person
// can read and diff. It holds everything needed to reproduce a decision — the feature set (by
// name, in FeatureVector order), the gates that define the features, the stumps (feature,
// threshold, polarity, α) and the strong-classifier factor — plus the training provenance.
//
//   urbanslam-laser-loop-model 1
//   # free comment lines (e.g. the command that produced the file)
//   r_max_m 30
//   g_max_dist_m 2.5
//   g_min_size 3
//   beam_increment_deg 1
//   log_features 1                               (optional; absent: 0, the plain features)
//   submap_window_m 10                           (optional; absent: 0, each scan alone)
//   factor 0.5
//   provenance <key> <value to end of line>      (any number)
//   features 79 area average_range ... range_q95  (a prefix of this build's list: older models list 20)
//   stumps 3
//   stump area 1.25 +1 0.693147
//   stump size 14.5 -1 0.405465
//   stump range_quantile_l1 30.5 +1 1.2           (a distance, Comparisons.h)
//   end
//
// Loading is strict: an unknown key, a missing required key, a feature list that is not a prefix
// of this build's, a stump on a feature the list lacks, a bad number, a stump count that does not match or a missing `end` (a truncated
// file) each throw common::InputError naming the file and line.
#include <string>
#include <utility>
#include <vector>

#include "urbanslam/laser_loop/ScanFeatures.h"
#include "urbanslam/laser_loop/StrongClassifier.h"

namespace urbanslam::laser_loop {

constexpr int kModelFormatVersion = 1;
constexpr const char* kModelMagic = "urbanslam-laser-loop-model";

struct ClassifierModel {
  FeatureParams params;
  double factor = 0.5;  // eq. 3.30's factor: match when the normalised vote >= factor
  // > 0: features of the virtual 360° scan over this much recent odometry (SubmapScan.h).
  double submap_window_m = 0;
  StrongClassifier classifier;
  std::vector<std::pair<std::string, std::string>> provenance;  // key, value (one line each)
  std::vector<std::string> comments;                            // written as "# ..." lines

  std::string provenanceValue(const std::string& key) const;
};

// Written atomically (common::AtomicFile); numbers with 17 significant digits so a reload
// reproduces every decision bit for bit.
void saveModel(const ClassifierModel& model, const std::string& path);
std::string modelToText(const ClassifierModel& model);
ClassifierModel loadModel(const std::string& path);
// `source` names the text in error messages.
ClassifierModel parseModel(const std::string& text, const std::string& source);

}  // namespace urbanslam::laser_loop
