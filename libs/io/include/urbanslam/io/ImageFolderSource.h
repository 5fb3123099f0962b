#pragma once
// A folder of image files as a log: one CameraImage per file, in natural name order (2.jpg
// before 10.jpg), so camera-only sequences (e.g. rawlogs/rtabmap-loop-excerpt/) run through the
// same pipeline as rawlogs. Such folders carry no clock: the timestamp of the n-th image is n
// (0-based) seconds, the same convention as vision_loop's image sequences.
#include <string>
#include <vector>

#include "urbanslam/io/DataSource.h"

namespace urbanslam::io {

class ImageFolderSource : public DataSource {
 public:
  // Throws common::InputError when the folder holds no image files.
  explicit ImageFolderSource(const std::string& folder);
  bool next(Measurement& out) override;
  double progress() const override;
  std::string format() const override;
  size_t size() const { return files_.size(); }

  // True when `folder` is a directory holding at least one image file.
  static bool looksLike(const std::string& folder);

 private:
  std::vector<std::string> files_;
  size_t at_ = 0;
};

// True for the file extensions we read as images (what OpenCV's and MRPT's loaders handle).
bool isImageFileName(const std::string& name);
// Natural order: digit runs compare as numbers ("img2" < "img10").
bool naturalLess(const std::string& a, const std::string& b);
// The image files of a folder in natural name order (empty when there are none).
std::vector<std::string> imageFilesIn(const std::string& folder);

}  // namespace urbanslam::io
