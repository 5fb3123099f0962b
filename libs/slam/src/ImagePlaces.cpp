#include "urbanslam/slam/ImagePlaces.h"

#include <opencv2/core.hpp>

#include "urbanslam/vision_loop/VocabularyFile.h"

namespace urbanslam::slam {

ImagePlaces::ImagePlaces(const Map& map, ImagePlaceOptions options) : map_(map), options_(std::move(options)) {
  for (const Keyframe& k : map_.keyframes()) images_in_map_ += k.has_image && !k.image_words.empty();
}

void ImagePlaces::addImage(const io::CameraImage& image) {
  if (!mapHasImages() || !image.pixels || image.width <= 0 || image.height <= 0) return;
  latest_ = image;
  latest_words_.reset();
}

void ImagePlaces::load() {
  // The vocabulary the map's words came from (a run resolves an empty path to the shipped one).
  const std::string path = options_.image_loop.vocabulary.empty() ? vision_loop::kDefaultVocabularyPath : options_.image_loop.vocabulary;
  vocabulary_ = std::make_shared<const vision_loop::Vocabulary>(vision_loop::loadVocabulary(path));
  extractor_ =
      std::make_unique<vision_loop::FeatureExtractor>(vision_loop::featureOptions(options_.image_loop, vocabulary_->descriptorType()));
  database_ = std::make_unique<vision_loop::ImageDatabase>(vocabulary_->wordCount());
  const auto& keyframes = map_.keyframes();
  for (size_t i = 0; i < keyframes.size(); ++i) {
    if (!keyframes[i].has_image || keyframes[i].image_words.empty()) continue;
    database_->add(keyframes[i].image_words);
    keyframe_of_.push_back(i);
  }
}

std::vector<ImagePlace> ImagePlaces::query(double t, double not_before) {
  if (!latest_ || latest_->timestamp < not_before || t - latest_->timestamp > options_.max_age_s) return {};
  if (!database_) load();
  if (!latest_words_) {
    const cv::Mat gray(latest_->height, latest_->width, CV_8U, const_cast<uint8_t*>(latest_->pixels->data()));
    latest_words_ = vocabulary_->transform(extractor_->extract(gray).descriptors);
  }
  ++queries_;
  vision_loop::QueryOptions q;
  q.max_results = options_.max_places;
  q.min_score = options_.min_score;
  std::vector<ImagePlace> out;
  for (const vision_loop::QueryResult& r : database_->query(*latest_words_, q)) out.push_back({keyframe_of_[r.image], r.score});
  return out;
}

}  // namespace urbanslam::slam
