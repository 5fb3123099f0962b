#include "urbanslam/io/ImageFolderSource.h"

#include <mrpt/img/CImage.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "MrptConversions.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/io/ImageHeader.h"

namespace urbanslam::io {

namespace fs = std::filesystem;

namespace {
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}
}  // namespace

bool isImageFileName(const std::string& name) {
  static const char* kExt[] = {".jpg", ".jpeg", ".png", ".bmp", ".pgm", ".ppm", ".pbm", ".tif", ".tiff", ".webp"};
  const std::string e = lower(fs::path(name).extension().string());
  return std::find(std::begin(kExt), std::end(kExt), e) != std::end(kExt);
}

bool naturalLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      size_t i2 = i, j2 = j;
      while (i2 < a.size() && std::isdigit(static_cast<unsigned char>(a[i2]))) ++i2;
      while (j2 < b.size() && std::isdigit(static_cast<unsigned char>(b[j2]))) ++j2;
      std::string na = a.substr(i, i2 - i), nb = b.substr(j, j2 - j);
      na.erase(0, std::min(na.find_first_not_of('0'), na.size()));
      nb.erase(0, std::min(nb.find_first_not_of('0'), nb.size()));
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = i2, j = j2;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::vector<std::string> imageFilesIn(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return files;
  for (const auto& e : fs::directory_iterator(folder, ec))
    if (e.is_regular_file() && isImageFileName(e.path().filename().string())) files.push_back(e.path().string());
  std::sort(files.begin(), files.end(), [](const std::string& a, const std::string& b) {
    return naturalLess(fs::path(a).filename().string(), fs::path(b).filename().string());
  });
  return files;
}

bool ImageFolderSource::looksLike(const std::string& folder) { return !imageFilesIn(folder).empty(); }

ImageFolderSource::ImageFolderSource(const std::string& folder) : DataSource(folder), files_(imageFilesIn(folder)) {
  if (files_.empty()) throw common::InputError(folder + ": folder holds no image files");
}

bool ImageFolderSource::next(Measurement& out) {
  if (at_ >= files_.size()) return false;
  const std::string& p = files_[at_];
  checkImageFile(p);
  mrpt::img::CImage im;
  if (!im.loadFromFile(p, 0)) throw common::InputError(p + ": cannot read image");
  CameraImage img = detail::toGray(im, static_cast<double>(at_), "CAMERA", p);
  img.source = p;
  out = std::move(img);
  ++at_;
  return true;
}

double ImageFolderSource::progress() const { return files_.empty() ? 1.0 : static_cast<double>(at_) / files_.size(); }

std::string ImageFolderSource::format() const { return "image folder (" + std::to_string(files_.size()) + " images)"; }

}  // namespace urbanslam::io
