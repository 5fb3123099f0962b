#pragma once
// Image loop-closure detection for the SLAM front end: each keyframe image is described by its
// bag of words, compared against all earlier frames (or the candidates the filter proposes from
// the pose estimate and its uncertainty), and a match is reported only when it is safe (§4.2.6
// spatial consistency, following DBoW2's scheme, Gálvez-López & Tardós 2012):
//  1. normalised score η_j = s(v_t, v_j) / s(v_t, v_{t−1}): the similarity to frame j relative to
//     the similarity to the previous frame (the best any true match can expect), so a single
//     threshold α works in cluttered and in bland scenes alike;
//  2. candidates with η ≥ α and close in time are grouped into islands (a place is seen in
//     several consecutive frames); the island with the largest summed score wins;
//  3. temporal consistency: the winning islands of the last `temporal_consistency` queries must
//     agree (overlap or be close);
//  4. geometric verification (ratio-test matches + RANSAC fundamental matrix) of the island's
//     best images.
// With sequence_frames L > 1 (3 by default), step 2 ranks by the sequence score η̄
// (SequenceScore.h) instead of η: the last L queries must have matched the frames before the
// candidate, in order. That is the temporal check by default; step 3 (k = temporal_consistency)
// is then off. On the RTAB-Map loop it removes the one confident false match that limited
// DBoW2's scheme (libs/vision_loop/README.md).
// A detection proposes a loop closure; laser alignment then measures the relative pose.
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "urbanslam/vision_loop/BagOfWords.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"
#include "urbanslam/vision_loop/GeometricVerification.h"
#include "urbanslam/vision_loop/ImageDatabase.h"
#include "urbanslam/vision_loop/SequenceScore.h"
#include "urbanslam/vision_loop/Vocabulary.h"

namespace urbanslam::vision_loop {

struct LoopDetectorOptions {
  float min_normalized_score = 0.3f;   // α (DBoW2's default)
  float min_prior_score = 0.005f;      // s(v_t, v_{t−1}) below this: nothing to normalise with, skip
  int exclude_recent_frames = 10;      // the last frames are the current place, not a loop
  size_t max_query_results = 50;       // top-k asked from the database
  int island_gap_frames = 3;           // matches at most this far apart form one island
  int temporal_consistency = 0;        // k: earlier consecutive queries whose islands must agree
  int max_island_distance_frames = 3;  // islands of consecutive queries agree when this close
  int max_query_gap_frames = 2;        // queries further apart are not "consecutive"
  int sequence_frames = 3;             // L: queries whose matches must advance together (1: off)
  bool geometric_verification = true;
  int verify_candidates = 3;  // best images of the winning island tried in turn
  VerificationOptions verification;
};

enum class LoopStatus {
  Detected,
  NoFeatures,          // the image gave no usable words
  DatabaseTooSmall,    // nothing older than the excluded recent frames yet
  LowPriorScore,       // s(v_t, v_{t−1}) < min_prior_score
  NoCandidates,        // no earlier image with η ≥ α
  NotConsistent,       // the island disagrees with the previous queries'
  VerificationFailed,  // no island image passed geometric verification
};
const char* loopStatusName(LoopStatus s);

struct LoopResult {
  LoopStatus status = LoopStatus::NoFeatures;
  ImageId query = 0;
  ImageId match = 0;           // best image of the winning island (when there is one)
  float score = 0;             // s(v_t, v_match)
  float normalized_score = 0;  // η of the match
  float sequence_score = 0;    // η̄ of the match (= η without sequence matching)
  VerificationResult verification;
  bool detected() const { return status == LoopStatus::Detected; }
};

struct FrameTimings {
  double extraction_ms = 0, quantization_ms = 0, query_ms = 0, verification_ms = 0;
  double total() const { return extraction_ms + quantization_ms + query_ms + verification_ms; }
};

class LoopDetector {
 public:
  using VerificationCache = std::map<std::pair<ImageId, ImageId>, VerificationResult>;

  LoopDetector(std::shared_ptr<const Vocabulary> vocabulary, const FeatureOptions& features, const LoopDetectorOptions& options = {});

  // Extracts features, quantises, queries, then adds the frame to the database. `candidates`:
  // when given, only these earlier images are considered (from the filter's pose uncertainty).
  LoopResult process(const cv::Mat& image, const std::vector<ImageId>* candidates = nullptr);
  // Same with features and bag already computed (evaluation sweeps reuse them).
  LoopResult process(ImageFeatures features, BagOfWords bag, const std::vector<ImageId>* candidates = nullptr);

  const FrameTimings& lastTimings() const { return timings_; }
  const ImageDatabase& database() const { return database_; }
  const Vocabulary& vocabulary() const { return *vocabulary_; }
  const FeatureExtractor& extractor() const { return extractor_; }
  const LoopDetectorOptions& options() const { return options_; }
  // The features of an image in the database (kept for geometric verification), so a detected
  // pair can be measured as well (PlanarRelativePose.h) without extracting them again.
  const ImageFeatures& features(ImageId id) const { return frames_.at(id); }
  // Verification results keyed by (query, match), shared between detectors fed the same frames
  // (a threshold sweep verifies each pair once).
  void shareVerificationCache(std::shared_ptr<VerificationCache> cache) { cache_ = std::move(cache); }

 private:
  struct Island {
    ImageId first = 0, last = 0;
    float score = 0;
    std::vector<QueryResult> members;  // best first
  };
  bool consistentWithPrevious(const Island& island, ImageId query);

  std::shared_ptr<const Vocabulary> vocabulary_;
  FeatureExtractor extractor_;
  LoopDetectorOptions options_;
  ImageDatabase database_;
  std::vector<ImageFeatures> frames_;  // kept for geometric verification
  BagOfWords previous_bag_;
  SequenceScore sequence_;
  std::vector<ScoredImage> query_results_;  // this frame's, for the sequence history
  FrameTimings timings_;
  std::shared_ptr<VerificationCache> cache_;
  // Temporal window (DBoW2): the last query that produced an island, that island, and how many
  // consecutive queries agreed so far.
  bool window_open_ = false;
  ImageId window_query_ = 0;
  Island window_island_;
  int window_count_ = 0;
};

}  // namespace urbanslam::vision_loop
