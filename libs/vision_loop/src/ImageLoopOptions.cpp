#include "urbanslam/vision_loop/ImageLoopOptions.h"

namespace urbanslam::vision_loop {

void declareImageLoopOptions(common::OptionsSchema& s, ImageLoopOptions& o) {
  s.add("vocabulary", o.vocabulary, {}, "vocabulary file (build-vocabulary); empty: share/vision_loop/sift_k10_L4.usvoc");
  s.add("max_features", o.max_features, 10, 100000, "features", "strongest features kept per image");
  s.add("max_image_side_px", o.max_image_side_px, 0, 100000, "px", "larger images are downscaled first; 0: never");
  s.add("min_image_side_px", o.min_image_side_px, 0, 100000, "px", "smaller images are upscaled before detection; 0: never");
  s.add("min_normalized_score", o.min_normalized_score, 0.0, 100.0, "", "alpha: score relative to the previous frame's");
  s.add("exclude_recent_frames", o.exclude_recent_frames, 0, 1000000, "frames", "the last frames are never loop candidates");
  s.add("temporal_consistency", o.temporal_consistency, 0, 100, "queries", "earlier consecutive queries whose islands must agree");
  s.add("sequence_frames", o.sequence_frames, 1, 100, "frames",
        "sequence matching: the last n queries must match earlier frames in order (1: off)");
  s.add("island_gap_frames", o.island_gap_frames, 0, 1000, "frames", "matches this close form one island");
  s.add("max_island_distance_frames", o.max_island_distance_frames, 0, 1000, "frames",
        "islands of consecutive queries agree when this close");
  s.add("max_query_results", o.max_query_results, 1, 100000, "images", "top-k images asked from the database");
  s.add("geometric_verification", o.geometric_verification, "verify a match with a RANSAC fundamental matrix");
  s.add("verify_candidates", o.verify_candidates, 1, 100, "images", "best images of the winning island tried");
  s.add("ratio", o.ratio, 0.1, 1.0, "", "Lowe's ratio test for descriptor matches");
  s.add("ransac_threshold_px", o.ransac_threshold_px, 0.1, 100.0, "px", "max distance to the epipolar line");
  s.add("min_inliers", o.min_inliers, 8, 100000, "matches", "fundamental-matrix inliers needed to accept");
  s.add("metric_pose", o.metric_pose,
        "a camera closure measures the full planar pose when the earlier keyframe's neighbouring image gives its features a depth "
        "(the odometry between them the scale) and the estimate knows the pair within [loop_closure] appearance_min_sigma_m; "
        "else bearing and heading only");
  s.add("metric_floor_forward_m", o.metric_floor_forward_m, 0.0, 100.0, "m",
        "floor on the full pose's standard deviation along the camera's axis (added in quadrature)");
  s.add("metric_floor_left_m", o.metric_floor_left_m, 0.0, 100.0, "m", "... across it");
  s.add("metric_floor_heading_deg", o.metric_floor_heading_deg, 0.0, 180.0, "deg", "... and of its heading");
}

FeatureOptions featureOptions(const ImageLoopOptions& o, DescriptorType type) {
  FeatureOptions f;
  f.type = type;
  f.max_features = o.max_features;
  f.max_image_side_px = o.max_image_side_px;
  f.min_image_side_px = o.min_image_side_px;
  return f;
}

LoopDetectorOptions detectorOptions(const ImageLoopOptions& o) {
  LoopDetectorOptions d;
  d.min_normalized_score = static_cast<float>(o.min_normalized_score);
  d.exclude_recent_frames = o.exclude_recent_frames;
  d.temporal_consistency = o.temporal_consistency;
  d.sequence_frames = o.sequence_frames;
  d.island_gap_frames = o.island_gap_frames;
  d.max_island_distance_frames = o.max_island_distance_frames;
  d.max_query_results = static_cast<size_t>(o.max_query_results);
  d.geometric_verification = o.geometric_verification;
  d.verify_candidates = o.verify_candidates;
  d.verification.ratio = o.ratio;
  d.verification.ransac_threshold_px = o.ransac_threshold_px;
  d.verification.min_inliers = o.min_inliers;
  return d;
}

}  // namespace urbanslam::vision_loop
