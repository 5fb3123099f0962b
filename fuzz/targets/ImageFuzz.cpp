// Image file contents: the input is one image file in a folder, read as a camera log. Its
// header is checked before the decoder allocates anything (io::checkImageFile), so a corrupt
// size cannot take gigabytes; decoding itself is OpenCV's.
#include <filesystem>

#include "FuzzSupport.h"
#include "urbanslam/io/ImageFolderSource.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace urbanslam;
  const auto dir = fuzz::scratchDir() / "images";
  std::filesystem::create_directories(dir);
  // The name only makes the folder a camera log: the header is read by content.
  const std::string path = fuzz::writeInput("images/0001.png", data, size);
  fuzz::expectCleanOutcome(path, [&] {
    io::ImageFolderSource source(dir.string());
    io::Measurement m;
    while (source.next(m)) {
    }
  });
  return 0;
}
