#include "urbanslam/io/SpillLog.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace urbanslam;

namespace {

struct Reading {
  double t = 0;
  std::uint64_t tag = 0;
  std::string label;  // variable length: chunks of different sizes in the file
};

struct ReadingCodec {
  static void write(common::BinaryWriter& w, const Reading& r) {
    w.f64(r.t);
    w.u64(r.tag);
    w.string(r.label);
  }
  static Reading read(common::BinaryReader& r) {
    Reading x;
    x.t = r.f64();
    x.tag = r.u64();
    x.label = r.string();
    return x;
  }
};

using Log = io::SpillLog<Reading, ReadingCodec>;

std::vector<Reading> randomReadings(size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> t(0, 1e6);
  std::uniform_int_distribution<int> len(0, 40);
  std::vector<Reading> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = {t(rng), rng(), std::string(static_cast<size_t>(len(rng)), static_cast<char>('a' + i % 26))};
  return out;
}

void expectEqual(const std::vector<Reading>& a, const std::vector<Reading>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].t, b[i].t) << i;
    EXPECT_EQ(a[i].tag, b[i].tag) << i;
    EXPECT_EQ(a[i].label, b[i].label) << i;
  }
}

}  // namespace

// The reference is the same readings kept in a vector: walked back, the log gives each one as
// appended, in order, across the chunks written to the file and those still in memory.
TEST(SpillLog, GivesBackEveryEntryInOrderAcrossTheFileAndMemory) {
  const auto readings = randomReadings(1000);
  Log log("readings", {}, 16);
  for (size_t i = 0; i < readings.size(); ++i) {
    log.push_back(readings[i]);
    ASSERT_EQ(log.size(), i + 1);
  }
  std::vector<Reading> walked;
  log.forEach([&](const Reading& r) { walked.push_back(r); });
  expectEqual(walked, readings);
  expectEqual(log.toVector(), readings);
  // Walked again: reading back does not consume the file.
  expectEqual(log.toVector(), readings);
}

// What stays in memory is bounded by the chunk, whatever was appended: the rest is in the file.
TEST(SpillLog, HoldsAtMostTwoChunksInMemory) {
  Log log("readings", {}, 8);
  for (const Reading& r : randomReadings(203)) log.push_back(r);
  size_t in_memory = 0;
  log.amendNewest([&](Reading&) { return ++in_memory, true; });
  EXPECT_GE(in_memory, 8u);
  EXPECT_LT(in_memory, 16u);
  EXPECT_EQ(203 - in_memory, 8 * ((203 - in_memory) / 8));  // whole chunks in the file
}

// The newest entries can be amended until they reach the file, and only as far as asked.
TEST(SpillLog, AmendsTheNewestEntriesWhileAsked) {
  auto readings = randomReadings(100);
  Log log("readings", {}, 10);
  for (const Reading& r : readings) log.push_back(r);
  int calls = 0;
  log.amendNewest([&](Reading& r) {
    ++calls;
    r.tag = 42;
    return calls < 3;
  });
  EXPECT_EQ(calls, 3);
  for (size_t i = readings.size() - 3; i < readings.size(); ++i) readings[i].tag = 42;
  expectEqual(log.toVector(), readings);
}

TEST(SpillLog, ClearedStartsAgainEmpty) {
  Log log("readings", {}, 4);
  for (const Reading& r : randomReadings(50)) log.push_back(r);
  log.clear();
  EXPECT_TRUE(log.empty());
  EXPECT_TRUE(log.toVector().empty());
  const auto again = randomReadings(30);
  for (const Reading& r : again) log.push_back(r);
  expectEqual(log.toVector(), again);
}

TEST(SpillLog, ASpillFolderThatCannotBeWrittenIsNamed) {
  Log log("odometry readings", "/nonexistent/spill", 4);
  try {
    for (const Reading& r : randomReadings(20)) log.push_back(r);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/spill"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("odometry readings"), std::string::npos) << e.what();
  }
}
