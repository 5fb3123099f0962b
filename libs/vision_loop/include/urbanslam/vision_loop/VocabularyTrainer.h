#pragma once
// Offline training of a vocabulary (thesis Algorithm 3): descriptors of many images unrelated to
// the run → hierarchical k-means tree → IDF weights from how many training images contain each
// word. Run once; the run-time side only loads the result.
#include <opencv2/core.hpp>
#include <vector>

#include "urbanslam/vision_loop/HierarchicalKMeans.h"
#include "urbanslam/vision_loop/Vocabulary.h"

namespace urbanslam::vision_loop {

// `per_image`: CV_8U descriptor matrices, one per training image (rows: descriptors).
// Throws common::InputError when there are no descriptors or they do not fit `type`.
Vocabulary trainVocabulary(const std::vector<cv::Mat>& per_image, DescriptorType type, const KMeansOptions& options,
                           const ProgressFn& progress = {});

// IDF w_i = ln(N / N_i) over the images of `per_image`, N_i = images containing word i. A word
// no training image reaches (possible where k-means partitions and the greedy descent differ)
// gets ln(N), the weight of the rarest observed word.
std::vector<float> computeIdf(const Vocabulary& vocabulary, const std::vector<cv::Mat>& per_image, int threads = 0);

}  // namespace urbanslam::vision_loop
