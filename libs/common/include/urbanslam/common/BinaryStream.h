#pragma once
// Byte-exact binary encoding for saved state: every value little-endian whatever the host
// (integers shifted out byte by byte, doubles as their IEEE-754 bit pattern), so a file written
// on one machine reads the same on another and a value read back is the value written.
//
// The reader works on bytes already in memory and never trusts a count: every read checks the
// bytes left, and count() refuses a number of items that could not fit in them, so a corrupt
// or crafted file ends in an InputError naming the file, never a huge allocation or a read
// past the end.
#include <Eigen/Core>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace urbanslam::common {

// FNV-1a, 64 bits: a payload checksum that needs no table and no library. `h`: the hash of the
// bytes before these, to hash a long payload piece by piece.
constexpr std::uint64_t kFnv1a64Start = 14695981039346656037ull;
std::uint64_t fnv1a64(const void* data, size_t size, std::uint64_t h = kFnv1a64Start);

// Collects the bytes in memory, or (with a sink) passes them on to a seekable stream a
// megabyte at a time, so that saving a map of any size needs no copy of it in memory; a
// section's length is then patched in the stream.
class BinaryWriter {
 public:
  BinaryWriter() = default;
  explicit BinaryWriter(std::ostream* sink) : sink_(sink) {}

  void u8(std::uint8_t v) {
    bytes_.push_back(static_cast<char>(v));
    if (sink_ && bytes_.size() >= kFlushBytes) flush();
  }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void size(size_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f32(float v);
  void f64(double v);
  void string(const std::string& s);
  void raw(const void* data, size_t n) {
    bytes_.append(static_cast<const char*>(data), n);
    if (sink_ && bytes_.size() >= kFlushBytes) flush();
  }
  template <int R, int C>
  void matrix(const Eigen::Matrix<double, R, C>& m) {
    static_assert(R > 0 && C > 0, "fixed-size matrices only; dynamic ones go through dense()");
    for (int c = 0; c < C; ++c)
      for (int r = 0; r < R; ++r) f64(m(r, c));
  }
  // A dense matrix of any size: rows, columns, then the entries column by column.
  void dense(const Eigen::MatrixXd& m);

  // A tagged section: the tag, its length (patched by endSection), then whatever is written
  // until endSection().
  void beginSection(std::uint32_t tag);
  void endSection();

  // In memory only (no sink).
  const std::string& bytes() const { return bytes_; }
  std::string take() { return std::move(bytes_); }
  // Bytes written so far.
  size_t position() const { return flushed_ + bytes_.size(); }
  // Passes the bytes held to the sink (throws InputError when the stream fails).
  void flush();

 private:
  static constexpr size_t kFlushBytes = 1 << 20;
  std::ostream* sink_ = nullptr;
  std::string bytes_;
  size_t flushed_ = 0;                 // bytes already passed to the sink
  std::vector<size_t> open_sections_;  // positions of the open sections' length fields
};

// Told how far readers over a buffer have read, so that the buffer can give back what lies
// behind (MappedFile): reached(p) once a read passes `next`, which it then moves on.
struct ReadProgress {
  virtual ~ReadProgress() = default;
  virtual void reached(const unsigned char* p) = 0;
  const unsigned char* next = nullptr;
};

class BinaryReader {
 public:
  // Error messages read "NAME: PROBLEM: what", e.g. "run/map.usmap: corrupt map: ...".
  // `progress` (optional, shared with the readers of its sections) hears how far reads got.
  BinaryReader(const char* data, size_t size, std::string name, std::string problem = "corrupt data", ReadProgress* progress = nullptr);

  std::uint8_t u8();
  bool boolean();
  std::uint32_t u32();
  std::uint64_t u64();
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  // A size_t written by BinaryWriter::size (refused when it does not fit this host's size_t).
  size_t size();
  float f32();
  double f64();
  std::string string();
  void raw(void* out, size_t n);
  template <int R, int C>
  Eigen::Matrix<double, R, C> matrix() {
    Eigen::Matrix<double, R, C> m;
    for (int c = 0; c < C; ++c)
      for (int r = 0; r < R; ++r) m(r, c) = f64();
    return m;
  }
  Eigen::MatrixXd dense();

  // A count of items that each take at least `min_bytes` in the file; refused when that many
  // cannot be in the bytes left.
  size_t count(size_t min_bytes);
  // The next section, which must carry `tag`; a reader over its bytes (this one moves past it).
  BinaryReader section(std::uint32_t tag);
  // Throws when bytes are left (a section read must consume exactly what was written).
  void expectEnd() const;
  size_t remaining() const { return size_ - pos_; }
  const std::string& name() const { return name_; }

  // Throws InputError "NAME: PROBLEM: WHAT" (also for the callers' validation of the values read).
  [[noreturn]] void fail(const std::string& what) const;

 private:
  const unsigned char* take(size_t n);

  const unsigned char* data_;
  size_t size_, pos_ = 0;
  std::string name_, problem_;
  ReadProgress* progress_ = nullptr;
};

// A section tag from four characters ("MAP "), so a hex dump shows what a section is.
constexpr std::uint32_t sectionTag(const char (&s)[5]) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(s[0])) | static_cast<std::uint32_t>(static_cast<unsigned char>(s[1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[2])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[3])) << 24;
}

}  // namespace urbanslam::common
