// The kept references of loop-closure alignments: one is handed out again only for a scan with
// the same returns, and then holds exactly the points a fresh one would.
#include <gtest/gtest.h>

#include <cmath>

#include "ConstantScan.h"
#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/slam/ScanReferences.h"

using namespace urbanslam;

namespace {

io::LaserScan wavyScan(double timestamp) {
  io::LaserScan s = test::constantScan(timestamp, 5.0f, 30.0);
  for (size_t i = 0; i < s.size(); ++i) s.ranges[i] = static_cast<float>(5.0 + 2.0 * std::sin(0.1 * static_cast<double>(i)));
  return s;
}

void expectSamePoints(const alignment::PointSet& a, const alignment::PointSet& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].p.x(), b[i].p.x());
    EXPECT_EQ(a[i].p.y(), b[i].p.y());
  }
}

TEST(ScanReferences, AReferenceIsReusedOnlyForAScanWithTheSameReturns) {
  const alignment::ScanModelOptions model;
  slam::ScanReferences refs(model, true, 4);
  const io::LaserScan scan = wavyScan(1.0);
  const auto first = refs.get(scan);
  expectSamePoints(first->points(), alignment::pointSetFromScan(scan, model, true));
  // The same returns at another time (the keyframe judged again): the same reference.
  EXPECT_EQ(refs.get(wavyScan(2.0)), first);
  // A return hidden (a moving car), a range changed, the sensor mounted elsewhere: another one,
  // with the points of that scan.
  io::LaserScan hidden = scan;
  hidden.valid[40] = 0;
  io::LaserScan moved = scan;
  moved.ranges[90] += 0.01f;
  io::LaserScan mounted = scan;
  mounted.sensor_pose.x = 0.5;
  for (const io::LaserScan* other : {&hidden, &moved, &mounted}) {
    const auto ref = refs.get(*other);
    EXPECT_NE(ref, first);
    expectSamePoints(ref->points(), alignment::pointSetFromScan(*other, model, true));
  }
  EXPECT_EQ(refs.hits(), 1u);
  EXPECT_EQ(refs.misses(), 4u);
  // Four kept (most recent first: mounted, moved, hidden, first); asking for the first makes it
  // the most recent, so one more scan drops the least recently used, hidden.
  EXPECT_EQ(refs.get(scan), first);
  io::LaserScan fifth = scan;
  fifth.ranges[10] = 3.0f;
  refs.get(fifth);
  EXPECT_EQ(refs.misses(), 5u);
  refs.get(moved);
  EXPECT_EQ(refs.misses(), 5u);  // still kept
  refs.get(hidden);
  EXPECT_EQ(refs.misses(), 6u);  // dropped, built again
}

}  // namespace
