// DurationHistogram against the exact percentiles of the same sample (common::percentile, which
// keeps every value): within the one per cent its bins promise, the maximum exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "urbanslam/common/BinaryStream.h"
#include "urbanslam/common/DurationHistogram.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"

using urbanslam::common::DurationHistogram;

namespace {

// Step times as a pipeline's look: most around a few milliseconds, a long tail, a few near zero.
std::vector<double> durations(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::lognormal_distribution<double> typical(std::log(3.0), 0.6);
  std::exponential_distribution<double> tail(0.02);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> v;
  for (size_t i = 0; i < n; ++i) {
    const double r = u(rng);
    v.push_back(r < 0.01 ? 1e-4 * u(rng) : r < 0.05 ? 20 + tail(rng) : typical(rng));
  }
  return v;
}

}  // namespace

TEST(DurationHistogram, PercentilesAreWithinOnePerCentOfTheSamples) {
  for (const size_t n : {1, 2, 7, 1000, 200000}) {
    const std::vector<double> v = durations(n, static_cast<unsigned>(n));
    DurationHistogram h;
    for (double x : v) h.add(x);
    EXPECT_EQ(h.count(), n);
    EXPECT_EQ(h.max(), *std::max_element(v.begin(), v.end()));
    EXPECT_EQ(h.percentile(100), h.max());
    for (const double p : {0.0, 1.0, 25.0, 50.0, 90.0, 99.0, 99.9}) {
      const double exact = urbanslam::common::percentile(v, p);
      // Below the first bin's edge (1 µs) every duration reads as that bin's centre.
      if (exact < 1e-3) {
        EXPECT_LT(h.percentile(p), 1.02e-3) << "n " << n << " p " << p;
      } else {
        EXPECT_NEAR(h.percentile(p), exact, 0.01 * exact) << "n " << n << " p " << p;
      }
    }
  }
  EXPECT_EQ(DurationHistogram().percentile(50), 0.0);
}

TEST(DurationHistogram, ReadsBackWhatItWrote) {
  DurationHistogram h;
  for (double x : durations(5000, 3)) h.add(x);
  urbanslam::common::BinaryWriter w;
  h.write(w);
  urbanslam::common::BinaryReader r(w.bytes().data(), w.bytes().size(), "histogram");
  DurationHistogram back;
  back.read(r);
  EXPECT_EQ(back.count(), h.count());
  EXPECT_EQ(back.max(), h.max());
  for (const double p : {10.0, 50.0, 99.0}) EXPECT_EQ(back.percentile(p), h.percentile(p));
}

// A histogram whose bins hold more durations than its count says is refused, naming the reason.
TEST(DurationHistogram, RefusesBinsThatDisagreeWithTheCount) {
  urbanslam::common::BinaryWriter w;
  w.size(3);   // count
  w.f64(1.0);  // max
  w.size(2);   // bins
  w.u64(2);
  w.u64(2);
  urbanslam::common::BinaryReader r(w.bytes().data(), w.bytes().size(), "histogram");
  DurationHistogram h;
  try {
    h.read(r);
    FAIL() << "read a histogram of 4 durations counted as 3";
  } catch (const urbanslam::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more durations than its count"), std::string::npos) << e.what();
  }
}
