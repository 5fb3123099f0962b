#pragma once
// Line- and token-wise reading of (possibly gzipped, possibly zipped) text, in constant memory.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "urbanslam/common/Numbers.h"

namespace urbanslam::io::detail {

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  // Reads up to n bytes; 0 at the end. Throws common::InputError on a read error / truncation.
  virtual size_t read(char* buf, size_t n) = 0;
  virtual double progress() const = 0;
};

// A plain or gzip-compressed file (zlib detects which).
std::unique_ptr<ByteStream> openGzFile(const std::string& path);
// One entry of a zip archive (libzip), e.g. LASER.txt inside victoria_park_ascii.zip.
std::unique_ptr<ByteStream> openZipEntry(const std::string& zip_path, const std::string& entry);

class TextScanner {
 public:
  TextScanner(std::unique_ptr<ByteStream> in, std::string name);
  // Next line without its terminator; false at the end of input.
  bool nextLine(std::string& line);
  // Next white-space separated token (ignores line structure); false at the end of input.
  bool nextToken(std::string& token);
  int lineNumber() const { return line_; }
  const std::string& name() const { return name_; }
  double progress() const { return in_->progress(); }

 private:
  bool fill();

  std::unique_ptr<ByteStream> in_;
  std::string name_;
  std::vector<char> buf_;
  size_t pos_ = 0, end_ = 0;
  int line_ = 0;
  bool eof_ = false;
};

// Splits a line on white space.
void splitFields(const std::string& line, std::vector<std::string>& fields);
// Strict numeric parsing (common::parseDecimal: decimal only, finite). Throws
// common::InputError with "where: what ..." for anything else or a value beyond max_abs.
double parseNumber(const std::string& field, const std::string& where, const char* what, double max_abs = common::kMaxMagnitude);
// A position (m) or an angle (rad): |value| <= common::kMaxCoordinate.
double parseCoordinate(const std::string& field, const std::string& where, const char* what);
long parseInteger(const std::string& field, const std::string& where, const char* what);

// n laser ranges from fields[first..]: NaN, infinite and negative ranges are corrupt input (an
// error), 0 and ranges at or beyond max_range are no-returns (valid = 0).
void parseRanges(const std::vector<std::string>& fields, size_t first, size_t n, double max_range, const std::string& where,
                 std::vector<float>& ranges, std::vector<uint8_t>& valid);

// Line-oriented logs: a line yields any number of records, which go out one at a time in file
// order. Parses lines with parse(line), which appends to pending, until one yields a record.
template <class Record, class ParseLine>
bool nextRecord(TextScanner& text, std::vector<Record>& pending, size_t& pos, Record& out, ParseLine&& parse) {
  while (pos >= pending.size()) {
    pending.clear();
    pos = 0;
    std::string line;
    if (!text.nextLine(line)) return false;
    parse(line);
  }
  out = std::move(pending[pos++]);
  return true;
}

}  // namespace urbanslam::io::detail
