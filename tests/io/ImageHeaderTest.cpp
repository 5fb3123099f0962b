#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <system_error>
#include <opencv2/imgcodecs.hpp>

#include "urbanslam/common/Error.h"
#include "urbanslam/io/ImageFolderSource.h"
#include "urbanslam/io/ImageHeader.h"

using namespace urbanslam;
namespace fs = std::filesystem;

namespace {

// This process's scratch folder, removed when the process ends (each test runs in its own).
struct ScratchFolder {
  const fs::path path = fs::temp_directory_path() / ("urbanslam-image-header-" + std::to_string(::getpid()));
  ~ScratchFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
} scratch_folder;

fs::path scratch(const std::string& name) {
  fs::create_directories(scratch_folder.path);
  return scratch_folder.path / name;
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void writeAll(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

}  // namespace

// OpenCV's encoders are the reference: every format it writes is read back at its size, without
// decoding, and agrees with what OpenCV's decoder returns.
TEST(ImageHeader, ReadsTheSizeOfEveryFormatOpenCvWrites) {
  cv::Mat colour(23, 37, CV_8UC3, cv::Scalar(10, 120, 200));
  cv::Mat grey(23, 37, CV_8U, cv::Scalar(99));
  for (const std::string ext : {".png", ".jpg", ".bmp", ".pgm", ".ppm", ".pbm", ".tif", ".webp"}) {
    const fs::path p = scratch("image" + ext);
    ASSERT_TRUE(cv::imwrite(p.string(), ext == ".ppm" ? colour : grey)) << ext;
    const io::ImageSize s = io::checkImageFile(p.string());
    const cv::Mat decoded = cv::imread(p.string(), cv::IMREAD_UNCHANGED);
    EXPECT_EQ(s.width, decoded.cols) << ext;
    EXPECT_EQ(s.height, decoded.rows) << ext;
    EXPECT_EQ(s.width, 37) << ext;
    EXPECT_EQ(s.height, 23) << ext;
  }
  // The size comes from the content, not the name.
  const fs::path renamed = scratch("really-a-png.jpg");
  fs::copy_file(scratch("image.png"), renamed, fs::copy_options::overwrite_existing);
  EXPECT_STREQ(io::readImageSize(renamed.string()).format, "PNG");
}

// A 2 kB PNG whose header declares 40000 x 40000 pixels would make the decoder allocate 1.6 GB
// (4.8 GB in colour): it is refused from its header, naming the file.
TEST(ImageHeader, RefusesAHugeDeclaredSizeBeforeDecoding) {
  const fs::path p = scratch("huge.png");
  ASSERT_TRUE(cv::imwrite(p.string(), cv::Mat(8, 8, CV_8U, cv::Scalar(1))));
  std::string bytes = readAll(p);
  for (int k = 0; k < 2; ++k) {  // IHDR width and height, big-endian at 16 and 20
    const uint32_t v = 40000;
    for (int b = 0; b < 4; ++b) bytes[16 + 4 * k + b] = static_cast<char>((v >> (24 - 8 * b)) & 0xff);
  }
  const fs::path dir = scratch("huge-folder");
  fs::create_directories(dir);
  writeAll(dir / "0001.png", bytes);
  try {
    io::ImageFolderSource source(dir.string());
    io::Measurement m;
    source.next(m);
    FAIL() << "a 40000 x 40000 header was decoded";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("0001.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("40000 x 40000"), std::string::npos) << e.what();
  }
}

TEST(ImageHeader, TruncatedOrUnknownContentIsAnInputError) {
  const fs::path png = scratch("t.png");
  ASSERT_TRUE(cv::imwrite(png.string(), cv::Mat(8, 8, CV_8U, cv::Scalar(1))));
  const std::string bytes = readAll(png);
  for (size_t n : {0, 4, 8, 15, 20}) {
    const fs::path cut = scratch("cut" + std::to_string(n) + ".png");
    writeAll(cut, bytes.substr(0, n));
    EXPECT_THROW(io::readImageSize(cut.string()), common::InputError) << n;
  }
  const fs::path text = scratch("text.png");
  writeAll(text, "this is not an image\n");
  EXPECT_THROW(io::readImageSize(text.string()), common::InputError);
  const fs::path jpeg_no_frame = scratch("noframe.jpg");
  writeAll(jpeg_no_frame, std::string("\xff\xd8\xff\xda\x00\x02", 6));
  EXPECT_THROW(io::readImageSize(jpeg_no_frame.string()), common::InputError);
}
