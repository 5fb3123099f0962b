#include "urbanslam/vision_loop/GeometricVerification.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>

namespace urbanslam::vision_loop {

PointMatches matchFeatures(const ImageFeatures& a, const ImageFeatures& b, DescriptorType type, double ratio) {
  PointMatches out;
  if (a.descriptors.rows < 2 || b.descriptors.rows < 2) return out;
  cv::Mat da = a.descriptors, db = b.descriptors;
  int norm = cv::NORM_HAMMING;
  if (type == DescriptorType::Sift) {
    da.convertTo(da, CV_32F);
    db.convertTo(db, CV_32F);
    norm = cv::NORM_L2;
  }
  cv::BFMatcher matcher(norm, false);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(da, db, knn, 2);
  // Ratio test, then keep each feature of b at most once (the best) so that a repeated texture
  // cannot vote many times for the same point.
  std::vector<int> best_for_b(db.rows, -1);
  std::vector<float> best_dist(db.rows, 0.f);
  for (const auto& m : knn) {
    if (m.size() < 2 || m[0].distance >= ratio * m[1].distance) continue;
    const int j = m[0].trainIdx;
    if (best_for_b[j] < 0 || m[0].distance < best_dist[j]) best_for_b[j] = m[0].queryIdx, best_dist[j] = m[0].distance;
  }
  for (int j = 0; j < db.rows; ++j) {
    if (best_for_b[j] < 0) continue;
    out.a.push_back(a.keypoints[best_for_b[j]].pt);
    out.b.push_back(b.keypoints[j].pt);
    out.ia.push_back(best_for_b[j]);
    out.ib.push_back(j);
  }
  return out;
}

VerificationResult verifyPair(const ImageFeatures& a, const ImageFeatures& b, DescriptorType type, const VerificationOptions& options) {
  VerificationResult r;
  const PointMatches m = matchFeatures(a, b, type, options.ratio);
  const std::vector<cv::Point2f>&pa = m.a, &pb = m.b;
  r.matches = static_cast<int>(pa.size());
  if (r.matches < 8 || r.matches < options.min_inliers) return r;
  std::vector<uchar> mask;
  const cv::Mat f = cv::findFundamentalMat(pa, pb, cv::FM_RANSAC, options.ransac_threshold_px, options.ransac_confidence, mask);
  if (f.empty()) return r;
  r.inliers = cv::countNonZero(mask);
  r.accepted = r.inliers >= options.min_inliers;
  return r;
}

}  // namespace urbanslam::vision_loop
