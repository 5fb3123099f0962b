#include "urbanslam/io/ImageHeader.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include "urbanslam/common/Error.h"

namespace urbanslam::io {

namespace {

using common::InputError;

// Random access to the file's bytes; reading past the end is a truncated header.
class HeaderBytes {
 public:
  explicit HeaderBytes(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw InputError(path + ": cannot open image file");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(in_.tellg());
  }
  uint64_t size() const { return size_; }
  std::vector<uint8_t> at(uint64_t offset, size_t n) {
    if (offset > size_ || n > size_ - offset) throw InputError(path_ + ": truncated image header");
    std::vector<uint8_t> b(n);
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(n));
    if (!in_) throw InputError(path_ + ": cannot read image file");
    return b;
  }
  uint32_t u8(uint64_t o) { return at(o, 1)[0]; }
  uint32_t be16(uint64_t o) {
    const auto b = at(o, 2);
    return (uint32_t(b[0]) << 8) | b[1];
  }
  uint32_t le16(uint64_t o) {
    const auto b = at(o, 2);
    return (uint32_t(b[1]) << 8) | b[0];
  }
  uint32_t be32(uint64_t o) { return (be16(o) << 16) | be16(o + 2); }
  uint32_t le32(uint64_t o) { return (le16(o + 2) << 16) | le16(o); }
  bool startsWith(const char* magic, size_t n, uint64_t offset = 0) {
    if (offset > size_ || n > size_ - offset) return false;
    return std::memcmp(at(offset, n).data(), magic, n) == 0;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

ImageSize png(HeaderBytes& f) {
  if (!f.startsWith("IHDR", 4, 12)) throw InputError(f.path() + ": PNG without an IHDR header");
  return {f.be32(16), f.be32(20), "PNG"};
}

// JPEG: walk the marker segments to the first frame header (SOFn).
ImageSize jpeg(HeaderBytes& f) {
  uint64_t at = 2;
  while (true) {
    if (f.u8(at) != 0xFF) throw InputError(f.path() + ": corrupt JPEG marker");
    uint32_t marker = f.u8(at + 1);
    while (marker == 0xFF) marker = f.u8(++at + 1);  // fill bytes
    at += 2;
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) continue;  // no length field
    if (marker == 0xD9 || marker == 0xDA) throw InputError(f.path() + ": JPEG without a frame header");
    const uint32_t length = f.be16(at);
    if (length < 2) throw InputError(f.path() + ": corrupt JPEG segment length");
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) return {f.be16(at + 5), f.be16(at + 3), "JPEG"};
    at += length;
  }
}

ImageSize bmp(HeaderBytes& f) {
  const uint32_t dib = f.le32(14);
  if (dib == 12) return {f.le16(18), f.le16(20), "BMP"};
  const auto w = static_cast<int32_t>(f.le32(18));
  const auto h = static_cast<int32_t>(f.le32(22));  // negative: rows stored top-down
  return {w < 0 ? -static_cast<long long>(w) : w, h < 0 ? -static_cast<long long>(h) : h, "BMP"};
}

// PNM: "P1".."P6", then width and height as decimal text between whitespace and # comments.
ImageSize pnm(HeaderBytes& f) {
  uint64_t at = 2;
  long long dims[2] = {0, 0};
  for (long long& d : dims) {
    while (true) {
      const uint32_t c = f.u8(at);
      if (c == '#') {
        while (f.u8(at) != '\n') ++at;
      } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        ++at;
      } else {
        break;
      }
    }
    int digits = 0;
    for (uint32_t c = f.u8(at); c >= '0' && c <= '9'; c = f.u8(at)) {
      if (++digits > 9) throw InputError(f.path() + ": PNM size out of range");
      d = d * 10 + (c - '0');
      ++at;
    }
    if (digits == 0) throw InputError(f.path() + ": corrupt PNM header");
  }
  return {dims[0], dims[1], "PNM"};
}

// TIFF: the first image file directory's ImageWidth (256) and ImageLength (257) entries.
ImageSize tiff(HeaderBytes& f, bool little) {
  auto u16 = [&](uint64_t o) { return little ? f.le16(o) : f.be16(o); };
  auto u32 = [&](uint64_t o) { return little ? f.le32(o) : f.be32(o); };
  const uint64_t ifd = u32(4);
  const uint32_t entries = u16(ifd);
  long long w = 0, h = 0;
  for (uint32_t i = 0; i < entries; ++i) {
    const uint64_t e = ifd + 2 + 12ULL * i;
    const uint32_t tag = u16(e), type = u16(e + 2);
    if (tag != 256 && tag != 257) continue;
    const long long v = type == 3 ? u16(e + 8) : type == 4 ? u32(e + 8) : -1;
    if (v < 0) throw InputError(f.path() + ": TIFF size of an unexpected type");
    (tag == 256 ? w : h) = v;
  }
  return {w, h, "TIFF"};
}

ImageSize webp(HeaderBytes& f) {
  if (f.startsWith("VP8 ", 4, 12)) {
    if (!f.startsWith("\x9d\x01\x2a", 3, 23)) throw InputError(f.path() + ": corrupt WebP (VP8) header");
    return {f.le16(26) & 0x3fff, f.le16(28) & 0x3fff, "WebP"};
  }
  if (f.startsWith("VP8L", 4, 12)) {
    if (f.u8(20) != 0x2f) throw InputError(f.path() + ": corrupt WebP (VP8L) header");
    const uint32_t bits = f.le32(21);
    return {(bits & 0x3fff) + 1LL, ((bits >> 14) & 0x3fff) + 1LL, "WebP"};
  }
  if (f.startsWith("VP8X", 4, 12)) {
    const auto le24 = [&](uint64_t o) { return f.le16(o) | (f.u8(o + 2) << 16); };
    return {le24(24) + 1LL, le24(27) + 1LL, "WebP"};
  }
  throw InputError(f.path() + ": WebP of an unknown kind");
}

}  // namespace

ImageSize readImageSize(const std::string& path) {
  HeaderBytes f(path);
  ImageSize s;
  if (f.startsWith("\x89PNG\r\n\x1a\n", 8))
    s = png(f);
  else if (f.startsWith("\xff\xd8", 2))
    s = jpeg(f);
  else if (f.startsWith("BM", 2))
    s = bmp(f);
  else if (f.size() >= 2 && f.u8(0) == 'P' && f.u8(1) >= '1' && f.u8(1) <= '6')
    s = pnm(f);
  else if (f.startsWith("II*\0", 4))
    s = tiff(f, true);
  else if (f.startsWith("MM\0*", 4))
    s = tiff(f, false);
  else if (f.startsWith("RIFF", 4) && f.startsWith("WEBP", 4, 8))
    s = webp(f);
  else
    throw InputError(path + ": not a PNG, JPEG, BMP, PNM, TIFF or WebP image");
  if (s.width <= 0 || s.height <= 0) throw InputError(path + ": " + s.format + " image of size zero");
  return s;
}

ImageSize checkImageFile(const std::string& path) {
  const ImageSize s = readImageSize(path);
  if (s.width > kMaxImageSide || s.height > kMaxImageSide || s.width * s.height > kMaxImagePixels)
    throw InputError(path + ": " + s.format + " image of " + std::to_string(s.width) + " x " + std::to_string(s.height) +
                     " pixels (the most a camera image may have is " + std::to_string(kMaxImagePixels / 1000000) +
                     " megapixels, " + std::to_string(kMaxImageSide) + " a side)");
  return s;
}

}  // namespace urbanslam::io
