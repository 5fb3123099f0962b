#include "urbanslam/vision_loop/ImageSequence.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"

namespace fs = std::filesystem;

namespace urbanslam::vision_loop {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

class FileListSequence : public ImageSequence {
 public:
  explicit FileListSequence(std::vector<std::string> files) : files_(std::move(files)) {}
  bool next(NamedImage& out) override {
    if (at_ >= files_.size()) return false;
    const std::string& p = files_[at_++];
    out.path = p;
    out.name = fs::path(p).stem().string();
    out.timestamp = static_cast<double>(at_ - 1);
    out.gray = cv::imread(p, cv::IMREAD_GRAYSCALE);
    if (out.gray.empty()) throw common::InputError(p + ": cannot read image");
    return true;
  }
  size_t sizeHint() const override { return files_.size(); }
  double progress() const override { return files_.empty() ? 1.0 : double(at_) / files_.size(); }

 private:
  std::vector<std::string> files_;
  size_t at_ = 0;
};

class LogSequence : public ImageSequence {
 public:
  explicit LogSequence(std::unique_ptr<io::DataSource> source) : source_(std::move(source)) {}
  bool next(NamedImage& out) override {
    io::Measurement m;
    while (source_->next(m)) {
      const auto* img = std::get_if<io::CameraImage>(&m);
      if (!img || !img->pixels || img->width <= 0 || img->height <= 0) continue;
      ++count_;
      out.path = source_->path();
      out.name = img->source.empty() ? std::to_string(count_) : fs::path(img->source).stem().string();
      out.timestamp = img->timestamp;
      out.gray = cv::Mat(img->height, img->width, CV_8U, const_cast<uint8_t*>(img->pixels->data())).clone();
      return true;
    }
    return false;
  }
  size_t sizeHint() const override { return 0; }
  double progress() const override { return source_->progress(); }

 private:
  std::unique_ptr<io::DataSource> source_;
  size_t count_ = 0;
};

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

std::unique_ptr<ImageSequence> openImageSequence(const std::string& path) {
  if (!fs::exists(path)) throw common::InputError(path + ": no such file or folder");
  if (fs::is_directory(path)) {
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(path))
      if (e.is_regular_file() && isImageFileName(e.path().filename().string())) files.push_back(e.path().string());
    if (files.empty()) throw common::InputError(path + ": folder holds no image files");
    std::sort(files.begin(), files.end(), [](const std::string& a, const std::string& b) {
      return naturalLess(fs::path(a).filename().string(), fs::path(b).filename().string());
    });
    return std::make_unique<FileListSequence>(std::move(files));
  }
  if (isImageFileName(path)) return std::make_unique<FileListSequence>(std::vector<std::string>{path});
  const std::string ext = lower(fs::path(path).extension().string());
  if (ext == ".txt" || ext == ".lst" || ext == ".list") {
    std::ifstream in(path);
    if (!in) throw common::InputError(path + ": cannot open image list");
    const fs::path base = fs::path(path).parent_path();
    std::vector<std::string> files;
    std::string line;
    while (std::getline(in, line)) {
      const auto h = line.find('#');
      if (h != std::string::npos) line.erase(h);
      while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
      size_t s = 0;
      while (s < line.size() && std::isspace(static_cast<unsigned char>(line[s]))) ++s;
      line.erase(0, s);
      if (line.empty()) continue;
      fs::path p(line);
      files.push_back((p.is_absolute() ? p : base / p).string());
    }
    if (files.empty()) throw common::InputError(path + ": image list is empty");
    return std::make_unique<FileListSequence>(std::move(files));
  }
  return std::make_unique<LogSequence>(io::openDataSource(path));
}

}  // namespace urbanslam::vision_loop
