#pragma once
// The laser loop-closure detector the SLAM pipeline uses. Features are computed
// once per keyframe and stored; a query compares the current scan's features with a candidate
// set of stored keyframes (or with all of them) using the trained strong classifier.
//
// Storage is one float column per feature the classifier uses, so screening a large map is a
// streaming pass: each stump becomes "is the keyframe's feature within ±threshold of the
// query's", evaluated on blocks of keyframes held in cache. A distance stump (Comparisons.h)
// reads a column of distances computed once per screen from its descriptor's feature columns.
// screen() works in single precision; score() reads the same stored floats and scores in double
// precision, so the two differ only for a |Δf| within float rounding of a threshold. Keeping the
// features in double as well cost 246 bytes per keyframe (heaptrack, a 30 km drive) and changed
// no closure of the 1 and 10 km² cities (their trajectories and closures are identical, cmp).
#include <cstddef>
#include <string>
#include <vector>

#include "urbanslam/io/LaserScan.h"
#include "urbanslam/laser_loop/ClassifierModel.h"
#include "urbanslam/laser_loop/Comparisons.h"

namespace urbanslam::laser_loop {

// The trained default models, relative to the project home (the repo, or $URBANSLAM_HOME): one for
// any laser, and one trained on lasers that see all around (share/laser_loop/README.md).
constexpr const char* kDefaultModelPath = "share/laser_loop/default.model";
constexpr const char* kDefault360ModelPath = "share/laser_loop/default-360.model";

class LoopDetector {
 public:
  // Throws common::InputError for a model trained on virtual submap scans (submap_window_m > 0):
  // the detector computes the features of each scan alone.
  explicit LoopDetector(ClassifierModel model);
  // Loads a model file (loadModel's errors).
  static LoopDetector fromFile(const std::string& path);

  const ClassifierModel& model() const { return model_; }
  double factor() const { return factor_; }
  // Overrides the model's factor (eq. 3.30) to trade detection for false alarm.
  void setFactor(double factor) { factor_ = factor; }

  FeatureVector features(const io::LaserScan& scan) const { return computeFeatures(scan, model_.params); }
  // Several lasers of one instant (front + rear): merged about the vehicle origin first.
  FeatureVector features(const std::vector<io::LaserScan>& scans) const {
    return scans.size() == 1 ? features(scans[0]) : computeFeatures(mergeScans(scans, model_.params.beam_increment_deg), model_.params);
  }
  // Stores a keyframe; ids are 0, 1, 2, ... in insertion order. Only the features the model
  // uses are kept (a thesis model: 20 of them), in single precision, so a map of 10⁶ keyframes
  // holds what it needs.
  size_t addKeyframe(const io::LaserScan& scan) { return addKeyframe(features(scan)); }
  size_t addKeyframe(const FeatureVector& f);
  size_t size() const { return count_; }
  // A stored keyframe's features: those the model uses (rounded to single precision), the others 0.
  FeatureVector keyframe(size_t id) const;
  void reserve(size_t n);

  // Normalised vote Σα_t c_t / Σα_t of the pair (query, keyframe id), in [0, 1].
  double score(const FeatureVector& query, size_t id) const;
  // The same for two stored keyframes (the query is keyframe query_id).
  double score(size_t query_id, size_t id) const;

  struct Match {
    size_t id = 0;
    double score = 0;
  };
  // Candidates whose score reaches the factor, best score first (ties: lower id first).
  std::vector<Match> query(const FeatureVector& query, const std::vector<size_t>& candidates) const;
  // Scores of all stored keyframes (scores[i] for keyframe i), single precision.
  void screen(const FeatureVector& query, std::vector<float>& scores) const;
  // All keyframes reaching the factor, best first.
  std::vector<Match> queryAll(const FeatureVector& query) const;

 private:
  struct CompiledStump {
    int column = 0;     // a feature's column, or
    int distance = -1;  // >= 0: a distance's slot in distances_
    float threshold = 0;
    float alpha = 0;
    int polarity = 1;
  };
  ClassifierModel model_;
  double factor_ = 0.5;
  double alpha_total_ = 0;
  std::vector<int> used_features_;  // column c holds feature used_features_[c]
  struct UsedDistance {
    Distance distance;
    std::vector<int> columns;  // its features' columns, in the descriptor's order
  };
  std::vector<UsedDistance> distances_;
  std::vector<CompiledStump> stumps_;
  std::vector<std::vector<float>> columns_;  // per used feature, single precision
  size_t count_ = 0;
  void fillUsed(size_t id, FeatureVector& f) const;  // writes keyframe id's used features into f
};

}  // namespace urbanslam::laser_loop
