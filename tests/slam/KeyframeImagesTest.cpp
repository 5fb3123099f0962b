// Images go to the keyframe nearest in time: the streaming assignment (one keyframe late, two
// images held) must equal a brute-force one over the whole stream (each image to its nearest
// keyframe within the offset, ties to the earlier; each keyframe keeping its nearest image).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "urbanslam/slam/KeyframeImages.h"

using namespace urbanslam;

namespace {
io::CameraImage imageAt(double t) {
  io::CameraImage im;
  im.timestamp = t;
  im.width = im.height = 1;
  im.pixels = std::make_shared<const std::vector<uint8_t>>(1, 0);
  return im;
}
}  // namespace

TEST(KeyframeImages, EachKeyframeGetsItsNearestImage) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> gap_kf(0.3, 1.5), gap_im(0.05, 0.6);
  for (int trial = 0; trial < 20; ++trial) {
    // Two independent clocks: keyframes and camera.
    std::vector<double> kfs, ims;
    for (double t = 0; t < 30; t += gap_kf(rng)) kfs.push_back(t);
    for (double t = 0.1 * trial / 20; t < 30; t += gap_im(rng)) ims.push_back(t);
    const double max_offset = 0.25;
    // Reference: image -> nearest keyframe (within max_offset); keyframe -> its nearest such image.
    std::map<size_t, double> expected;
    for (double ti : ims) {
      size_t best = 0;
      for (size_t k = 1; k < kfs.size(); ++k)
        if (std::abs(kfs[k] - ti) < std::abs(kfs[best] - ti)) best = k;
      if (std::abs(kfs[best] - ti) > max_offset) continue;
      auto it = expected.find(best);
      if (it == expected.end() || std::abs(ti - kfs[best]) < std::abs(it->second - kfs[best])) expected[best] = ti;
    }
    // The stream, merged in time order (an image at the same time as a keyframe comes first).
    slam::KeyframeImageAssigner a(max_offset);
    std::map<size_t, double> got;
    size_t i = 0, k = 0;
    while (k < kfs.size() || i < ims.size()) {
      if (i < ims.size() && (k >= kfs.size() || ims[i] <= kfs[k])) {
        a.addImage(imageAt(ims[i++]));
      } else {
        if (auto d = a.keyframeAdded(k, kfs[k])) got[d->keyframe] = d->image.timestamp;
        ++k;
      }
    }
    if (auto d = a.finish()) got[d->keyframe] = d->image.timestamp;
    EXPECT_EQ(got, expected) << "trial " << trial;
    EXPECT_FALSE(expected.empty());
  }
}

TEST(KeyframeImages, CameraOnlyKeyframeOwnsItsImage) {
  slam::KeyframeImageAssigner a(0.5);
  const auto d = a.imageKeyframe(3, imageAt(7.0));
  EXPECT_EQ(d.keyframe, 3u);
  EXPECT_EQ(d.image.timestamp, 7.0);
  EXPECT_FALSE(a.finish().has_value());
}
