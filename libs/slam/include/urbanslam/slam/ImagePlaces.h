#pragma once
// Which places of a frozen map a camera image shows: the Tree of Words database of the map
// keyframes' images (their words, which the map keeps; thesis §4.2.4), queried with the latest
// image of the log being localized. A laser place search over the whole map can leave places it
// cannot tell apart (a city's streets, a building's corridors); the camera sees what a scan does
// not (facades, signs, doors), so the keyframes its image resembles narrow the search to a few
// places (Localizer.h). Nothing is loaded until the map has image words and the log an image.
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "urbanslam/io/Measurements.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/vision_loop/FeatureExtractor.h"
#include "urbanslam/vision_loop/ImageDatabase.h"
#include "urbanslam/vision_loop/ImageLoopOptions.h"
#include "urbanslam/vision_loop/Vocabulary.h"

namespace urbanslam::slam {

struct ImagePlaceOptions {
  bool enabled = true;
  // The map's vocabulary and feature settings ([image_loop]): the words must be the map's.
  vision_loop::ImageLoopOptions image_loop;
  // An image taken longer than this before the scan may show where the vehicle was, not is (a
  // camera at 2 Hz has one within half a second of every scan).
  double max_age_s = 0.5;
  size_t max_places = 5;    // the keyframes whose images score best ...
  float min_score = 0.05f;  // ... at least this (1 − ½‖q − d‖₁; images with few words in common score a few hundredths)
  // The vehicle within this of such a keyframe: a camera sees the facades it passes from metres
  // along the street, and the keyframe's image was taken where the keyframe was.
  double radius_m = 10.0;
};

struct ImagePlace {
  size_t keyframe = 0;  // index in the map
  float score = 0;
};

class ImagePlaces {
 public:
  // `map` must outlive this; it is only read.
  ImagePlaces(const Map& map, ImagePlaceOptions options);

  // The latest camera image (its pixels shared, not copied); its words are computed when a query
  // needs them, once.
  void addImage(const io::CameraImage& image);
  // The map keyframes whose images look most like the latest image, best first, when that image
  // was taken at `not_before` or later and at most max_age_s before `t`; empty otherwise (no
  // image, too old, a map without images).
  std::vector<ImagePlace> query(double t, double not_before = -HUGE_VAL);
  // The map holds image words and the options allow their use.
  bool mapHasImages() const { return options_.enabled && images_in_map_ > 0; }
  size_t queries() const { return queries_; }

 private:
  void load();

  const Map& map_;
  ImagePlaceOptions options_;
  size_t images_in_map_ = 0;
  std::shared_ptr<const vision_loop::Vocabulary> vocabulary_;
  std::unique_ptr<vision_loop::FeatureExtractor> extractor_;
  std::unique_ptr<vision_loop::ImageDatabase> database_;
  std::vector<size_t> keyframe_of_;  // database image id → map keyframe
  std::optional<io::CameraImage> latest_;
  std::optional<vision_loop::BagOfWords> latest_words_;
  size_t queries_ = 0;
};

}  // namespace urbanslam::slam
