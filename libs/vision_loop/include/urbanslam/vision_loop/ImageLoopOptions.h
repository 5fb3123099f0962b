#pragma once
// The image loop detector's settings as flat ini keys (units in the names), declared for the
// project's OptionsSchema so the pipeline can expose them in one section, e.g.
//   s.section("image_loop", "Tree of Words image loop-closure detection");
//   vision_loop::declareImageLoopOptions(s, options.image_loop);
#include <string>

#include "urbanslam/common/OptionsSchema.h"
#include "urbanslam/vision_loop/LoopDetector.h"

namespace urbanslam::vision_loop {

// Relative to the project home (applications resolve it; the library uses it as given).
constexpr const char* kDefaultVocabularyPath = "share/vision_loop/sift_k10_L4.usvoc";

struct ImageLoopOptions {
  std::string vocabulary;  // empty: share/vision_loop/sift_k10_L4.usvoc
  int max_features = 500;
  int max_image_side_px = 1024;
  int min_image_side_px = 320;        // smaller images are upscaled before detection
  double min_normalized_score = 0.3;  // α
  int exclude_recent_frames = 10;
  int temporal_consistency = 0;
  int sequence_frames = 3;
  int island_gap_frames = 3;
  int max_island_distance_frames = 3;
  int max_query_results = 50;
  bool geometric_verification = true;
  int verify_candidates = 3;
  double ratio = 0.8;
  double ransac_threshold_px = 3.0;
  int min_inliers = 20;
  // A camera closure's full planar pose (MetricRelativePose.h) when the earlier keyframe's
  // neighbouring image gives its features a depth; else bearing and heading only. The floors:
  // what the covariance does not show, calibrated on a held-out simulated city
  // (bench/vision_loop/run_eval.sh).
  bool metric_pose = true;
  double metric_floor_forward_m = 0.022;
  double metric_floor_left_m = 0.012;
  double metric_floor_heading_deg = 0.2;
};

// Adds the keys to the schema's current section.
void declareImageLoopOptions(common::OptionsSchema& schema, ImageLoopOptions& options);

// The extractor settings for a vocabulary of descriptor `type` (which decides SIFT or ORB).
FeatureOptions featureOptions(const ImageLoopOptions& options, DescriptorType type);
LoopDetectorOptions detectorOptions(const ImageLoopOptions& options);

}  // namespace urbanslam::vision_loop
