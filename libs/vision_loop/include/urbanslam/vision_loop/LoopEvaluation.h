#pragma once
// Evaluation of image loop detection against ground truth: precision–recall over the detection
// threshold α, recall at 100 % precision (the figure DBoW2 reports), CSV and PNG of the curve.
//
// Ground truth file: `#` comments; one line per image that closes loops: the image's name
// (file name without extension), then the names of the earlier images it matches.
// A detection at frame t with match j is a true positive when j is listed for t, a false
// positive otherwise (also when t is not listed at all). Recall = TP / (frames listed in the
// ground truth that occur in the sequence).
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "urbanslam/vision_loop/LoopDetector.h"

namespace urbanslam::vision_loop {

class GroundTruthLoops {
 public:
  // Throws common::InputError for a missing file or a line with a name and nothing else.
  static GroundTruthLoops load(const std::string& path);
  void add(const std::string& query, const std::string& match) { matches_[query].insert(match); }
  bool closesLoop(const std::string& query) const { return matches_.count(query) > 0; }
  bool isMatch(const std::string& query, const std::string& match) const;
  size_t size() const { return matches_.size(); }
  const std::map<std::string, std::set<std::string>>& all() const { return matches_; }

 private:
  std::map<std::string, std::set<std::string>> matches_;
};

// A frame with everything the detector needs precomputed (features and words do not depend on α).
struct EvaluationFrame {
  std::string name;
  ImageFeatures features;
  BagOfWords bag;
  double extraction_ms = 0, quantization_ms = 0;
};

struct PrPoint {
  double threshold = 0;  // α
  size_t detections = 0, true_positives = 0, false_positives = 0;
  double precision = 1, recall = 0;
};

struct Detection {
  std::string query, match;
  float score = 0, normalized_score = 0;
  int inliers = 0;
  bool correct = false;
};

struct SweepResult {
  std::vector<PrPoint> curve;           // one point per threshold, in the order given
  size_t positives = 0;                 // frames that close a loop in the ground truth
  double recall_at_precision_1 = 0;     // best recall among points without false positives
  double threshold_at_precision_1 = 0;  // the smallest α reaching it
  std::vector<Detection> detections_at_precision_1;
  PrPoint at_default;  // at the detector's own α
  std::vector<Detection> detections_at_default;
  double mean_query_ms = 0, mean_verification_ms = 0;  // at the detector's own α
};

// Runs the detector over `frames` once per threshold (α = min_normalized_score); geometric
// verification results are shared between the runs.
SweepResult sweepThresholds(const std::vector<EvaluationFrame>& frames, const GroundTruthLoops& truth,
                            std::shared_ptr<const Vocabulary> vocabulary, const FeatureOptions& features,
                            const LoopDetectorOptions& options, const std::vector<double>& thresholds);

// CSV: threshold,detections,true_positives,false_positives,precision,recall
void writePrCurveCsv(const std::vector<PrPoint>& curve, const std::string& path);
// PNG plot of precision against recall (drawn with OpenCV).
void writePrCurvePng(const std::vector<PrPoint>& curve, const std::string& title, const std::string& path);

}  // namespace urbanslam::vision_loop
