// Image lists (a .txt naming one image per line, relative to the list) and the natural name
// order of image folders. The scratch folder holds a small valid image and a corrupt one for
// the list to name; at most a few images are decoded per input to keep the fuzzer fast.
#include <algorithm>
#include <sstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "FuzzSupport.h"
#include "urbanslam/io/ImageFolderSource.h"
#include "urbanslam/vision_loop/ImageSequence.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  static const bool images = [] {
    cv::imwrite((fuzz::scratchDir() / "1.png").string(), cv::Mat(8, 8, CV_8U, cv::Scalar(128)));
    fuzz::writeInput("2.png", "\x89PNG\r\n\x1a\n corrupt");
    return true;
  }();
  (void)images;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string path = fuzz::writeInput("input.txt", text);
  // A bad entry's error names the image file, not the list.
  fuzz::expectCleanOutcome("", [&] {
    auto seq = vision_loop::openImageSequence(path);
    vision_loop::NamedImage im;
    for (int k = 0; k < 4 && seq->next(im); ++k) {
    }
  });
  // The folder order must be a strict weak order on any names (std::sort needs one).
  std::vector<std::string> names;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line) && names.size() < 64;) names.push_back(line);
  for (const auto& a : names) {
    if (io::naturalLess(a, a)) fuzz::fail("naturalLess is not irreflexive", a);
    for (const auto& b : names)
      if (io::naturalLess(a, b) && io::naturalLess(b, a)) fuzz::fail("naturalLess is not asymmetric", a + " / " + b);
  }
  std::sort(names.begin(), names.end(), io::naturalLess);
  for (const auto& n : names) io::isImageFileName(n);
  return 0;
}
