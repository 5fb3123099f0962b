#pragma once
// Geometric verification of a candidate pair (part of the spatial consistency of §4.2.6): two
// images of the same place share many features that one epipolar geometry explains; two images
// that merely share a texture (bricks, foliage, office carpet) do not. Descriptor matches pass
// Lowe's ratio test, then RANSAC fits a fundamental matrix and the pair is accepted with at
// least `min_inliers` inliers.
#include <opencv2/core.hpp>

#include "urbanslam/vision_loop/FeatureExtractor.h"

namespace urbanslam::vision_loop {

struct VerificationOptions {
  double ratio = 0.8;                // Lowe's ratio: best match distance < ratio · second best
  double ransac_threshold_px = 3.0;  // max distance of a point to its epipolar line
  double ransac_confidence = 0.99;
  int min_inliers = 20;  // accept with at least this many epipolar inliers
};

struct VerificationResult {
  bool accepted = false;
  int matches = 0;  // after the ratio test (and the one-to-one check)
  int inliers = 0;  // of the fundamental matrix
};

// Descriptor matches of a to b that pass Lowe's ratio test, each feature of b kept at most once
// (its best), as pixel positions in each image.
struct PointMatches {
  std::vector<cv::Point2f> a, b;
  std::vector<int> ia, ib;  // the keypoints they are, in a and in b
};
PointMatches matchFeatures(const ImageFeatures& a, const ImageFeatures& b, DescriptorType type, double ratio);

VerificationResult verifyPair(const ImageFeatures& a, const ImageFeatures& b, DescriptorType type, const VerificationOptions& options = {});

}  // namespace urbanslam::vision_loop
