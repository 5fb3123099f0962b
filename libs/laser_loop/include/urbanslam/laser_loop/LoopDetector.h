#pragma once
// The laser loop-closure detector the SLAM pipeline uses. Features are computed
// once per keyframe and stored; a query compares the current scan's features with a candidate
// set of stored keyframes (or with all of them) using the trained strong classifier.
//
// Storage is one float column per feature the classifier uses, so screening a large map is a
// streaming pass: each stump becomes "is the keyframe's feature within ±threshold of the
// query's", evaluated on blocks of keyframes held in cache. screen() works in single precision;
// its decisions can differ from the double-precision score() only for a |Δf| within float
// rounding of a threshold.
#include <cstddef>
#include <string>
#include <vector>

#include "urbanslam/io/LaserScan.h"
#include "urbanslam/laser_loop/ClassifierModel.h"

namespace urbanslam::laser_loop {

// The trained default model, relative to the project home (the repo, or $URBANSLAM_HOME).
constexpr const char* kDefaultModelPath = "share/laser_loop/default.model";

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
  // Stores a keyframe; ids are 0, 1, 2, ... in insertion order.
  size_t addKeyframe(const io::LaserScan& scan) { return addKeyframe(features(scan)); }
  size_t addKeyframe(const FeatureVector& f);
  size_t size() const { return keyframes_.size(); }
  const FeatureVector& keyframe(size_t id) const { return keyframes_.at(id); }
  void reserve(size_t n);

  // Normalised vote Σα_t c_t / Σα_t of the pair (query, keyframe id), in [0, 1].
  double score(const FeatureVector& query, size_t id) const;

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
    int column = 0;
    float threshold = 0;
    float alpha = 0;
    int polarity = 1;
  };
  ClassifierModel model_;
  double factor_ = 0.5;
  double alpha_total_ = 0;
  std::vector<int> used_features_;  // column c holds feature used_features_[c]
  std::vector<CompiledStump> stumps_;
  std::vector<std::vector<float>> columns_;
  std::vector<FeatureVector> keyframes_;
};

}  // namespace urbanslam::laser_loop
