#pragma once
// An image file's size, read from its header before anything decodes it. The decoders (OpenCV,
// and MRPT through it) allocate the whole image from the header alone, and accept up to 2^30
// pixels: a corrupt or hostile header of a few bytes would make a run allocate gigabytes.
// Checking the header first keeps every command under its memory bound on any image file.
#include <cstddef>
#include <string>

namespace urbanslam::io {

struct ImageSize {
  long long width = 0;
  long long height = 0;
  const char* format = "";  // "PNG", "JPEG", "BMP", "PNM", "TIFF" or "WebP"
};

// The largest image a run accepts: 64 megapixels (a 9000 × 7000 camera), 32768 pixels a side.
constexpr long long kMaxImagePixels = 64LL * 1000 * 1000;
constexpr long long kMaxImageSide = 32768;

// Reads the size from the header of a PNG, JPEG, BMP, PNM (PGM/PPM/PBM), TIFF or WebP file, by
// its content (not its name). Throws common::InputError naming the file for any other content,
// a truncated header, or a size of zero.
ImageSize readImageSize(const std::string& path);

// readImageSize(), and an InputError naming the file when the image is larger than
// kMaxImagePixels or kMaxImageSide. Call before decoding a file.
ImageSize checkImageFile(const std::string& path);

}  // namespace urbanslam::io
