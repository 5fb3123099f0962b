#include "urbanslam/common/BinaryStream.h"

#include <cstring>
#include <limits>

#include "urbanslam/common/Error.h"

namespace urbanslam::common {

std::uint64_t fnv1a64(const void* data, size_t size, std::uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

void BinaryWriter::u32(std::uint32_t v) {
  for (int i = 0; i < 4; ++i) u8(static_cast<std::uint8_t>(v >> (8 * i)));
}

void BinaryWriter::u64(std::uint64_t v) {
  for (int i = 0; i < 8; ++i) u8(static_cast<std::uint8_t>(v >> (8 * i)));
}

void BinaryWriter::f32(float v) {
  static_assert(sizeof(float) == 4 && std::numeric_limits<float>::is_iec559, "IEEE-754 binary32 floats");
  std::uint32_t bits;
  std::memcpy(&bits, &v, 4);
  u32(bits);
}

void BinaryWriter::f64(double v) {
  static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559, "IEEE-754 binary64 doubles");
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  u64(bits);
}

void BinaryWriter::string(const std::string& s) {
  size(s.size());
  raw(s.data(), s.size());
}

void BinaryWriter::dense(const Eigen::MatrixXd& m) {
  size(static_cast<size_t>(m.rows()));
  size(static_cast<size_t>(m.cols()));
  for (Eigen::Index c = 0; c < m.cols(); ++c)
    for (Eigen::Index r = 0; r < m.rows(); ++r) f64(m(r, c));
}

void BinaryWriter::beginSection(std::uint32_t tag) {
  u32(tag);
  open_sections_.push_back(position());
  u64(0);  // patched by endSection
}

void BinaryWriter::flush() {
  if (!sink_ || bytes_.empty()) return;
  sink_->write(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
  if (!*sink_) throw InputError("cannot write the file (disk full?)");
  flushed_ += bytes_.size();
  bytes_.clear();
}

void BinaryWriter::endSection() {
  const size_t at = open_sections_.back();
  open_sections_.pop_back();
  const std::uint64_t length = position() - at - 8;
  char field[8];
  for (int i = 0; i < 8; ++i) field[i] = static_cast<char>(static_cast<std::uint8_t>(length >> (8 * i)));
  if (at >= flushed_) {
    std::memcpy(&bytes_[at - flushed_], field, 8);
    return;
  }
  // The length field went to the sink already: patch it there.
  sink_->seekp(static_cast<std::streamoff>(at));
  sink_->write(field, 8);
  sink_->seekp(0, std::ios::end);
  if (!*sink_) throw InputError("cannot write the file (disk full?)");
}

BinaryReader::BinaryReader(const char* data, size_t size, std::string name, std::string problem, ReadProgress* progress)
    : data_(reinterpret_cast<const unsigned char*>(data)), size_(size), name_(std::move(name)), problem_(std::move(problem)), progress_(progress) {}

void BinaryReader::fail(const std::string& what) const { throw InputError(name_ + ": " + problem_ + ": " + what); }

const unsigned char* BinaryReader::take(size_t n) {
  if (n > remaining()) fail("it ends " + std::to_string(n - remaining()) + " bytes before a value it announces");
  const unsigned char* p = data_ + pos_;
  pos_ += n;
  if (progress_ && p > progress_->next) progress_->reached(p);
  return p;
}

std::uint8_t BinaryReader::u8() { return *take(1); }

bool BinaryReader::boolean() {
  const std::uint8_t v = u8();
  if (v > 1) fail("a flag of value " + std::to_string(v));
  return v == 1;
}

std::uint32_t BinaryReader::u32() {
  const unsigned char* p = take(4);
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}

std::uint64_t BinaryReader::u64() {
  const unsigned char* p = take(8);
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

size_t BinaryReader::size() {
  const std::uint64_t v = u64();
  if (v > std::numeric_limits<size_t>::max()) fail("a size beyond this machine's");
  return static_cast<size_t>(v);
}

float BinaryReader::f32() {
  const std::uint32_t bits = u32();
  float v;
  std::memcpy(&v, &bits, 4);
  return v;
}

double BinaryReader::f64() {
  const std::uint64_t bits = u64();
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

std::string BinaryReader::string() {
  const size_t n = count(1);
  const unsigned char* p = take(n);
  return std::string(reinterpret_cast<const char*>(p), n);
}

void BinaryReader::raw(void* out, size_t n) {
  const unsigned char* p = take(n);
  if (n > 0) std::memcpy(out, p, n);  // an empty vector's data() may be null, and memcpy must not get one
}

Eigen::MatrixXd BinaryReader::dense() {
  const size_t rows = size(), cols = size();
  // An empty matrix reads no values, so the bytes left bound neither of its sizes: a cap does
  // (a 0 x 2^60 matrix from a file took minutes to walk its empty columns).
  constexpr size_t kMaxSide = size_t{1} << 31;
  if (rows > kMaxSide || cols > kMaxSide || (rows != 0 && cols > remaining() / 8 / rows))
    fail("a " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix in the bytes left");
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  if (m.size() == 0) return m;
  for (Eigen::Index c = 0; c < m.cols(); ++c)
    for (Eigen::Index r = 0; r < m.rows(); ++r) m(r, c) = f64();
  return m;
}

size_t BinaryReader::count(size_t min_bytes) {
  const size_t n = size();
  if (min_bytes == 0) min_bytes = 1;
  if (n > remaining() / min_bytes) fail("a count of " + std::to_string(n) + " items in " + std::to_string(remaining()) + " bytes");
  return n;
}

BinaryReader BinaryReader::section(std::uint32_t tag) {
  const std::uint32_t got = u32();
  if (got != tag) {
    std::string expected, found;
    for (int i = 0; i < 4; ++i) {
      const auto printable = [](std::uint32_t c) { return c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?'; };
      expected += printable((tag >> (8 * i)) & 0xff);
      found += printable((got >> (8 * i)) & 0xff);
    }
    fail("section '" + found + "' where '" + expected + "' belongs");
  }
  const size_t n = size();
  if (n > remaining()) fail("a section of " + std::to_string(n) + " bytes in " + std::to_string(remaining()));
  const unsigned char* p = take(n);
  return BinaryReader(reinterpret_cast<const char*>(p), n, name_, problem_, progress_);
}

void BinaryReader::expectEnd() const {
  if (remaining() != 0) fail(std::to_string(remaining()) + " bytes left over at the end of a section");
}

}  // namespace urbanslam::common
