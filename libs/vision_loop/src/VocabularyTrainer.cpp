#include "urbanslam/vision_loop/VocabularyTrainer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <thread>

#include "urbanslam/common/Error.h"

namespace urbanslam::vision_loop {

std::vector<float> computeIdf(const Vocabulary& vocabulary, const std::vector<cv::Mat>& per_image, int threads) {
  if (threads <= 0) threads = std::max(1u, std::thread::hardware_concurrency());
  const size_t words = vocabulary.wordCount();
  std::vector<std::atomic<uint32_t>> images_with(words);
  for (auto& a : images_with) a = 0;
  std::atomic<size_t> cursor{0};
  std::atomic<size_t> images{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&] {
      std::vector<WordId> seen;
      for (size_t i; (i = cursor++) < per_image.size();) {
        const cv::Mat& d = per_image[i];
        if (d.empty()) continue;
        ++images;
        seen.clear();
        for (int r = 0; r < d.rows; ++r) seen.push_back(vocabulary.quantize(d.ptr<uint8_t>(r)));
        std::sort(seen.begin(), seen.end());
        seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
        for (WordId w : seen) ++images_with[w];
      }
    });
  for (auto& th : pool) th.join();
  std::vector<float> idf(words);
  const double n = std::max<size_t>(1, images);
  for (size_t w = 0; w < words; ++w) idf[w] = static_cast<float>(std::log(n / std::max<uint32_t>(1, images_with[w])));
  return idf;
}

Vocabulary trainVocabulary(const std::vector<cv::Mat>& per_image, DescriptorType type, const KMeansOptions& options,
                           const ProgressFn& progress) {
  const int bytes = descriptorBytes(type);
  size_t total = 0, images = 0;
  for (const cv::Mat& d : per_image) {
    if (d.empty()) continue;
    if (d.type() != CV_8U || d.cols != bytes)
      throw common::InputError("training descriptors do not match " + descriptorName(type) + " (" + std::to_string(bytes) + " bytes)");
    total += d.rows;
    ++images;
  }
  if (total == 0) throw common::InputError("no training descriptors (no image gave any feature)");
  std::vector<uint8_t> all(total * bytes);
  size_t at = 0;
  for (const cv::Mat& d : per_image)
    for (int r = 0; r < d.rows; ++r, ++at) std::memcpy(all.data() + at * bytes, d.ptr<uint8_t>(r), bytes);
  DescriptorSet set{all.data(), total, bytes};
  VocabularyData data = buildVocabularyTree(set, type, options, [&](double f, const std::string& s) {
    if (progress) progress(0.95 * f, s);
  });
  data.training_images = images;
  Vocabulary tree(data);
  if (progress) progress(0.95, "IDF weights");
  data.idf = computeIdf(tree, per_image, options.threads);
  Vocabulary v(std::move(data));
  if (progress) progress(1.0, "done");
  return v;
}

}  // namespace urbanslam::vision_loop
