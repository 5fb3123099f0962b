#include "urbanslam/vision_loop/ImageSequence.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "urbanslam/common/Error.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/io/ImageHeader.h"

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
    io::checkImageFile(p);
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

std::unique_ptr<ImageSequence> openImageSequence(const std::string& path) {
  if (!fs::exists(path)) throw common::InputError(path + ": no such file or folder");
  if (fs::is_directory(path)) {
    std::vector<std::string> files = io::imageFilesIn(path);
    if (files.empty()) throw common::InputError(path + ": folder holds no image files");
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
