#include "urbanslam/common/BinaryStream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "urbanslam/common/Error.h"

using namespace urbanslam::common;

namespace {

std::string hexOf(const std::string& b) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (unsigned char c : b) {
    out += digits[c >> 4];
    out += digits[c & 15];
  }
  return out;
}

}  // namespace

// Little-endian whatever the host, doubles as their IEEE-754 bits (written out by hand here).
TEST(BinaryStream, WritesLittleEndianBytes) {
  BinaryWriter w;
  w.u32(0x01020304u);
  w.u64(0x0102030405060708ull);
  w.f64(1.0);    // 0x3ff0000000000000
  w.f32(-2.0f);  // 0xc0000000
  w.string("ab");
  EXPECT_EQ(hexOf(w.bytes()),
            "04030201"
            "0807060504030201"
            "000000000000f03f"
            "000000c0"
            "0200000000000000"
            "6162");
}

TEST(BinaryStream, ReadsBackWhatWasWritten) {
  BinaryWriter w;
  const double values[] = {0.1, -0.0, std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::infinity(), 1e308};
  for (double v : values) w.f64(v);
  w.f64(std::nan(""));
  w.i32(-5);
  w.i64(-1234567890123ll);
  w.boolean(true);
  Eigen::Matrix3d m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9.5;
  w.matrix(m);
  w.dense(Eigen::MatrixXd::Constant(2, 3, 0.25));
  w.beginSection(sectionTag("TEST"));
  w.string("inside");
  w.endSection();

  const std::string bytes = w.bytes();
  BinaryReader r(bytes.data(), bytes.size(), "x.bin");
  for (double v : values) {
    const double got = r.f64();
    EXPECT_EQ(std::signbit(got), std::signbit(v));
    EXPECT_EQ(got, v);
  }
  EXPECT_TRUE(std::isnan(r.f64()));
  EXPECT_EQ(r.i32(), -5);
  EXPECT_EQ(r.i64(), -1234567890123ll);
  EXPECT_TRUE(r.boolean());
  EXPECT_EQ((r.matrix<3, 3>()), m);
  EXPECT_EQ(r.dense(), Eigen::MatrixXd::Constant(2, 3, 0.25));
  BinaryReader s = r.section(sectionTag("TEST"));
  EXPECT_EQ(s.string(), "inside");
  s.expectEnd();
  r.expectEnd();
}

// Every read checks the bytes left: a short or lying input is an InputError naming it, and a
// count that cannot fit is refused before anything is allocated for it.
TEST(BinaryStream, RefusesReadsPastTheEndAndImpossibleCounts) {
  BinaryWriter w;
  w.u64(1ull << 60);  // a count, with nothing after it
  const std::string bytes = w.bytes();
  {
    BinaryReader r(bytes.data(), bytes.size(), "x.bin", "corrupt map");
    try {
      r.count(8);
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("x.bin: corrupt map: ", 0), 0u) << e.what();
    }
  }
  {
    BinaryReader r(bytes.data(), 4, "x.bin");
    EXPECT_THROW(r.u64(), InputError);
  }
  {
    BinaryReader r(bytes.data(), bytes.size(), "x.bin");
    EXPECT_THROW(r.string(), InputError);
  }
  {
    BinaryReader r(bytes.data(), bytes.size(), "x.bin");
    EXPECT_THROW(r.section(sectionTag("TEST")), InputError);  // the tag does not match
  }
  {
    BinaryWriter d;
    d.size(1ull << 40);
    d.size(1ull << 40);
    const std::string b = d.bytes();
    BinaryReader r(b.data(), b.size(), "x.bin");
    EXPECT_THROW(r.dense(), InputError);
  }
  {  // no values to bound its width by: refused at once, not walked column by column
    BinaryWriter d;
    d.size(0);
    d.size(1ull << 60);
    const std::string b = d.bytes();
    BinaryReader r(b.data(), b.size(), "x.bin");
    EXPECT_THROW(r.dense(), InputError);
  }
  {  // an empty matrix of modest sizes is still a matrix
    BinaryWriter d;
    d.dense(Eigen::MatrixXd(0, 3));
    const std::string b = d.bytes();
    BinaryReader r(b.data(), b.size(), "x.bin");
    const Eigen::MatrixXd m = r.dense();
    EXPECT_EQ(m.rows(), 0);
    EXPECT_EQ(m.cols(), 3);
  }
  {
    const std::string two = std::string("\x02", 1);
    BinaryReader r(two.data(), two.size(), "x.bin");
    EXPECT_THROW(r.boolean(), InputError);
  }
}

TEST(BinaryStream, Fnv1a64MatchesTheReferenceValues) {
  EXPECT_EQ(fnv1a64("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar", 6), 0x85944171f73967e8ull);
}

TEST(BinaryStream, Fnv1a64PieceByPieceEqualsWhole) {
  const std::string s = "a payload hashed in three pieces";
  const std::uint64_t h = fnv1a64(s.data() + 20, s.size() - 20, fnv1a64(s.data() + 7, 13, fnv1a64(s.data(), 7)));
  EXPECT_EQ(h, fnv1a64(s.data(), s.size()));
}

// Written through a sink, a megabyte at a time with the sections' lengths patched in the stream,
// the bytes are those of the writer that keeps everything in memory: nested sections, sections
// that end long after their length went to the stream, and ones that end before.
TEST(BinaryStream, StreamedWriterWritesTheSameBytes) {
  const auto fill = [](BinaryWriter& w) {
    w.beginSection(sectionTag("ONE "));
    for (int i = 0; i < 300000; ++i) w.f64(std::sin(i));  // 2.4 MB: flushed inside the section
    w.beginSection(sectionTag("TWO "));
    w.string("inner");
    w.endSection();
    w.endSection();
    w.beginSection(sectionTag("THRE"));
    w.u32(7);
    w.endSection();
  };
  BinaryWriter memory;
  fill(memory);
  std::stringstream s(std::ios::in | std::ios::out | std::ios::binary);
  BinaryWriter streamed(&s);
  fill(streamed);
  streamed.flush();
  EXPECT_EQ(streamed.position(), memory.bytes().size());
  EXPECT_TRUE(s.str() == memory.bytes());
  BinaryReader r(memory.bytes().data(), memory.bytes().size(), "x.bin");
  BinaryReader one = r.section(sectionTag("ONE "));
  EXPECT_EQ(one.remaining(), 300000u * 8 + 4 + 8 + 8 + 5);
}
