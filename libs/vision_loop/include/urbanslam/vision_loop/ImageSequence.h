#pragma once
// Where images come from: a folder (its image files in natural name order: 2.jpg before
// 10.jpg), an image list (text file, one path per line relative to the list, `#` comments), a
// single image file, or any log io::openDataSource reads (MRPT rawlogs: CObservationImage, left
// image of stereo pairs, external images). Images are delivered one at a time as 8-bit gray.
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "urbanslam/io/ImageFolderSource.h"

namespace urbanslam::vision_loop {

struct NamedImage {
  std::string name;  // file name without folder and extension; "<n>" (1-based) for embedded images
  std::string path;  // the file, or the log it came from
  double timestamp = 0;
  cv::Mat gray;
};

class ImageSequence {
 public:
  virtual ~ImageSequence() = default;
  // Next image; false at the end. Throws common::InputError for an unreadable image.
  virtual bool next(NamedImage& out) = 0;
  // Number of images when known up front, else 0.
  virtual size_t sizeHint() const = 0;
  // Fraction consumed, for progress bars.
  virtual double progress() const = 0;
};

// Throws common::InputError for a missing path or an empty folder/list.
std::unique_ptr<ImageSequence> openImageSequence(const std::string& path);

// Folder listing rules shared with io's image-folder log (the pipeline reads the same folders in
// the same order): accepted extensions, natural order ("img2" < "img10").
using io::isImageFileName;
using io::naturalLess;

}  // namespace urbanslam::vision_loop
