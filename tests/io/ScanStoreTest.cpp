#include "urbanslam/io/ScanStore.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <thread>

#include "urbanslam/common/Error.h"

using namespace urbanslam;

namespace {

io::LaserScan randomScan(std::mt19937& rng, size_t beams, double t) {
  std::uniform_real_distribution<float> range(0.1f, 60.0f);
  io::LaserScan s;
  s.timestamp = t;
  s.label = "LIDAR" + std::to_string(static_cast<int>(t) % 3);
  s.angle_min_rad = -M_PI;
  s.angle_increment_rad = 2 * M_PI / static_cast<double>(beams);
  s.max_range_m = 80;
  s.sensor_pose = {0.2, 0.0, t * 1e-3};
  s.ranges.resize(beams);
  s.valid.resize(beams);
  for (size_t i = 0; i < beams; ++i) {
    s.ranges[i] = i % 11 == 5 ? 80.0f : range(rng);
    s.valid[i] = i % 11 != 5;
  }
  return s;
}

// The reference: what the scan gives back when held compact in memory, without the store.
void expectSame(const io::LaserScan& a, const io::LaserScan& b, size_t id) {
  EXPECT_EQ(a.timestamp, b.timestamp) << id;
  EXPECT_EQ(a.label, b.label) << id;
  EXPECT_EQ(a.angle_min_rad, b.angle_min_rad) << id;
  EXPECT_EQ(a.angle_increment_rad, b.angle_increment_rad) << id;
  EXPECT_EQ(a.max_range_m, b.max_range_m) << id;
  EXPECT_EQ(a.sensor_pose.phi, b.sensor_pose.phi) << id;
  ASSERT_EQ(a.ranges, b.ranges) << id;
  ASSERT_EQ(a.valid, b.valid) << id;
}

}  // namespace

TEST(CompactScan, WritesAndReadsBackTheSameCodes) {
  std::mt19937 rng(3);
  const io::CompactScan c(randomScan(rng, 361, 17.25));
  common::BinaryWriter w;
  c.write(w);
  common::BinaryReader r(w.bytes().data(), w.bytes().size(), "bytes");
  const io::CompactScan back = io::CompactScan::read(r);
  r.expectEnd();
  expectSame(c.expand(), back.expand(), 0);
  EXPECT_EQ(back.validCount(), c.validCount());

  const std::string cut = w.bytes().substr(0, w.bytes().size() - 3);
  common::BinaryReader truncated(cut.data(), cut.size(), "cut");
  EXPECT_THROW(io::CompactScan::read(truncated), common::InputError);
}

// A store bounded to a few dozen scans holds 600: memory never exceeds the bound, the rest
// lives in the spill file, and every scan asked for, in any order and any number of times, is
// the scan added.
TEST(ScanStore, EveryScanComesBackAsAddedWhateverTheCacheHolds) {
  std::mt19937 rng(11);
  std::vector<io::LaserScan> reference;
  const size_t one = io::CompactScan(randomScan(rng, 361, 0)).memoryBytes();
  io::ScanStore store(40 * one);
  for (size_t i = 0; i < 600; ++i) {
    const io::CompactScan c(randomScan(rng, 361, static_cast<double>(i)));
    reference.push_back(c.expand());
    EXPECT_EQ(store.add(c), i);
    ASSERT_LE(store.residentBytes(), store.cacheBytes());
  }
  EXPECT_EQ(store.size(), 600u);
  EXPECT_GE(store.residentBytes(), 39 * one);  // the cache is used, not just bounded
  EXPECT_GT(store.spilledBytes(), 500 * 361 * 2);

  std::uniform_int_distribution<size_t> pick(0, 599);
  io::LaserScan buffer;
  for (int q = 0; q < 3000; ++q) {
    const size_t id = q < 600 ? static_cast<size_t>(q) : pick(rng);
    store.expandInto(id, buffer);
    expectSame(buffer, reference[id], id);
    ASSERT_EQ(store.validCount(id), reference[id].validCount());
    ASSERT_LE(store.residentBytes(), store.cacheBytes());
  }
  // Read back and evicted again: still written once.
  EXPECT_LT(store.spilledBytes(), 600u * one);
}

// With no cache at all every scan is on disk, and one handed out outlives its eviction.
TEST(ScanStore, AScanHandedOutOutlivesItsEviction) {
  std::mt19937 rng(5);
  io::ScanStore store(0);
  const io::LaserScan a = io::CompactScan(randomScan(rng, 181, 1)).expand();
  const io::LaserScan b = io::CompactScan(randomScan(rng, 181, 2)).expand();
  store.add(io::CompactScan(a));
  store.add(io::CompactScan(b));
  EXPECT_EQ(store.residentBytes(), 0u);
  const auto held = store.get(0);
  store.get(1);  // evicts 0 from the (empty) cache
  expectSame(held->expand(), a, 0);
  expectSame(store.expand(1), b, 1);
  store.clear();
  EXPECT_EQ(store.size(), 0u);
  EXPECT_EQ(store.spilledBytes(), 0u);
  store.add(io::CompactScan(b));
  store.add(io::CompactScan(a));
  expectSame(store.expand(1), a, 1);
}

// The global SLAM thread adds keyframes while another reads earlier ones.
TEST(ScanStore, ReadersAndAWriterShareIt) {
  std::mt19937 rng(7);
  std::vector<io::LaserScan> reference;
  for (size_t i = 0; i < 400; ++i) reference.push_back(io::CompactScan(randomScan(rng, 91, static_cast<double>(i))).expand());
  io::ScanStore store(30 * io::CompactScan(reference[0]).memoryBytes());
  for (size_t i = 0; i < 100; ++i) store.add(io::CompactScan(reference[i]));
  std::atomic<bool> bad{false};
  std::thread writer([&] {
    for (size_t i = 100; i < reference.size(); ++i) store.add(io::CompactScan(reference[i]));
  });
  std::vector<std::thread> readers;
  for (int t = 0; t < 2; ++t)
    readers.emplace_back([&, t] {
      std::mt19937 r(static_cast<unsigned>(t));
      io::LaserScan buffer;
      for (int q = 0; q < 2000; ++q) {
        const size_t n = store.size();
        const size_t id = std::uniform_int_distribution<size_t>(0, n - 1)(r);
        store.expandInto(id, buffer);
        if (buffer.ranges != reference[id].ranges || buffer.timestamp != reference[id].timestamp) bad = true;
      }
    });
  writer.join();
  for (auto& t : readers) t.join();
  EXPECT_FALSE(bad);
  EXPECT_EQ(store.size(), reference.size());
}

TEST(ScanStore, ASpillFolderThatCannotBeWrittenIsNamed) {
  std::mt19937 rng(1);
  io::ScanStore store(0, "/nonexistent/spill");
  try {
    store.add(io::CompactScan(randomScan(rng, 11, 0)));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/spill"), std::string::npos) << e.what();
  }
}
