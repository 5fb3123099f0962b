#include "TextScanner.h"

#include <zip.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Numbers.h"

namespace urbanslam::io::detail {

using common::InputError;

namespace {

class GzFileStream : public ByteStream {
 public:
  explicit GzFileStream(const std::string& path) : path_(path) {
    std::error_code ec;
    size_ = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(path + ": cannot open (" + ec.message() + ")");
    f_ = gzopen(path.c_str(), "rb");
    if (!f_) throw InputError(path + ": cannot open");
    gzbuffer(f_, 1 << 17);
  }
  ~GzFileStream() override {
    if (f_) gzclose(f_);
  }
  size_t read(char* buf, size_t n) override {
    const int got = gzread(f_, buf, static_cast<unsigned>(n));
    if (got < 0) {
      int err = 0;
      const char* msg = gzerror(f_, &err);
      throw InputError(path_ + ": read error (" + std::string(msg ? msg : "?") + ")");
    }
    if (got == 0) {
      int err = 0;
      gzerror(f_, &err);
      // zlib reports a gzip stream that ends early as Z_BUF_ERROR at EOF.
      if (err == Z_BUF_ERROR) throw InputError(path_ + ": truncated gzip file");
    }
    return static_cast<size_t>(got);
  }
  double progress() const override {
    if (size_ == 0) return 1.0;
    const double off = static_cast<double>(gzoffset(f_));
    return std::min(1.0, off / static_cast<double>(size_));
  }

 private:
  std::string path_;
  gzFile f_ = nullptr;
  uintmax_t size_ = 0;
};

class ZipEntryStream : public ByteStream {
 public:
  ZipEntryStream(const std::string& zip_path, const std::string& entry) : name_(zip_path + ":" + entry) {
    int err = 0;
    za_ = zip_open(zip_path.c_str(), ZIP_RDONLY, &err);
    if (!za_) throw InputError(zip_path + ": cannot open as a zip archive");
    zip_stat_t st;
    zip_stat_init(&st);
    // Entries may sit in a sub-folder of the archive: match on the file name.
    const zip_int64_t n = zip_get_num_entries(za_, 0);
    zip_int64_t index = -1;
    for (zip_int64_t i = 0; i < n && index < 0; ++i) {
      const char* nm = zip_get_name(za_, static_cast<zip_uint64_t>(i), 0);
      if (nm && std::filesystem::path(nm).filename() == entry) index = i;
    }
    if (index < 0) {
      zip_close(za_);
      throw InputError(zip_path + ": no entry named " + entry);
    }
    zip_stat_index(za_, static_cast<zip_uint64_t>(index), 0, &st);
    size_ = st.size;
    zf_ = zip_fopen_index(za_, static_cast<zip_uint64_t>(index), 0);
    if (!zf_) {
      zip_close(za_);
      throw InputError(name_ + ": cannot read");
    }
  }
  ~ZipEntryStream() override {
    if (zf_) zip_fclose(zf_);
    if (za_) zip_close(za_);
  }
  size_t read(char* buf, size_t n) override {
    const zip_int64_t got = zip_fread(zf_, buf, n);
    if (got < 0) throw InputError(name_ + ": read error (corrupt zip?)");
    done_ += static_cast<uint64_t>(got);
    return static_cast<size_t>(got);
  }
  double progress() const override { return size_ ? std::min(1.0, static_cast<double>(done_) / static_cast<double>(size_)) : 1.0; }

 private:
  std::string name_;
  zip_t* za_ = nullptr;
  zip_file_t* zf_ = nullptr;
  uint64_t size_ = 0, done_ = 0;
};

std::string formatLimit(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::unique_ptr<ByteStream> openGzFile(const std::string& path) { return std::make_unique<GzFileStream>(path); }

std::unique_ptr<ByteStream> openZipEntry(const std::string& zip_path, const std::string& entry) {
  return std::make_unique<ZipEntryStream>(zip_path, entry);
}

TextScanner::TextScanner(std::unique_ptr<ByteStream> in, std::string name) : in_(std::move(in)), name_(std::move(name)), buf_(1 << 16) {}

bool TextScanner::fill() {
  if (eof_) return false;
  end_ = in_->read(buf_.data(), buf_.size());
  pos_ = 0;
  if (end_ == 0) eof_ = true;
  return end_ > 0;
}

bool TextScanner::nextLine(std::string& line) {
  line.clear();
  bool any = false;
  for (;;) {
    if (pos_ >= end_ && !fill()) break;
    any = true;
    const char* start = buf_.data() + pos_;
    const char* stop = buf_.data() + end_;
    const char* nl = static_cast<const char*>(std::memchr(start, '\n', static_cast<size_t>(stop - start)));
    if (nl) {
      line.append(start, nl);
      pos_ += static_cast<size_t>(nl - start) + 1;
      break;
    }
    line.append(start, stop);
    pos_ = end_;
  }
  if (!any) return false;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  ++line_;
  return true;
}

bool TextScanner::nextToken(std::string& token) {
  token.clear();
  for (;;) {
    if (pos_ >= end_ && !fill()) return !token.empty();
    const char c = buf_[pos_++];
    const bool space = c == ' ' || c == '\t' || c == '\n' || c == '\r';
    if (c == '\n') ++line_;
    if (space) {
      if (!token.empty()) return true;
    } else {
      token.push_back(c);
    }
  }
}

void splitFields(const std::string& line, std::vector<std::string>& fields) {
  fields.clear();
  size_t i = 0;
  const size_t n = line.size();
  while (i < n) {
    while (i < n && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= n) break;
    size_t j = i;
    while (j < n && line[j] != ' ' && line[j] != '\t') ++j;
    fields.emplace_back(line, i, j - i);
    i = j;
  }
}

double parseNumber(const std::string& field, const std::string& where, const char* what, double max_abs) {
  const auto v = common::parseDecimal(field);
  if (!v) throw InputError(where + ": " + what + " '" + field + "' is not a number (plain decimal; hex, inf and NaN are not accepted)");
  if (std::abs(*v) > max_abs)
    throw InputError(where + ": " + what + " " + field + " is out of range (|value| > " + formatLimit(max_abs) + ")");
  return *v;
}

double parseCoordinate(const std::string& field, const std::string& where, const char* what) {
  return parseNumber(field, where, what, common::kMaxCoordinate);
}

long parseInteger(const std::string& field, const std::string& where, const char* what) {
  const auto v = common::parseWholeNumber(field);
  if (!v) throw InputError(where + ": " + what + " '" + field + "' is not a whole number");
  return *v;
}

void parseRanges(const std::vector<std::string>& f, size_t first, size_t n, double max_range, const std::string& where,
                 std::vector<float>& ranges, std::vector<uint8_t>& valid) {
  ranges.resize(n);
  valid.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double r = parseNumber(f[first + i], where, "range");
    if (r < 0) throw common::InputError(where + ": negative range " + f[first + i]);
    ranges[i] = static_cast<float>(r);
    valid[i] = (r > 0 && r < max_range) ? 1 : 0;
  }
}

}  // namespace urbanslam::io::detail
