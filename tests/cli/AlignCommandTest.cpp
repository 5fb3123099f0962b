// `urbanslam align` on a real corrected CARMEN log (skipped without the shared data), run as a
// user runs it: the executable, its exit code and output.
#include <gtest/gtest.h>

#include <filesystem>

#include "CliRunner.h"

using urbanslam::test::CliResult;
using urbanslam::test::runCli;

namespace {

const std::string kIntel = std::string(URBANSLAM_SHARED_DATA_DIR) + "/freiburg_slam_benchmark/corrected_logs/intel-corrected.log.gz";

}  // namespace

TEST(AlignCommand, JsonOnConsecutiveScansMatchesReference) {
  if (!std::filesystem::exists(kIntel)) GTEST_SKIP() << "shared data absent: " << kIntel;
  const CliResult r = runCli("align " + kIntel + " 100 101 --method plicp --json");
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* key :
       {"\"x\":", "\"y\":", "\"phi\":", "\"cov\":[[", "\"iterations\":", "\"time_ms\":", "\"converged\":true", "\"reference\":"})
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " in " << r.out;
}

TEST(AlignCommand, BadInputIsOneErrorLineAndExit2) {
  for (const std::string& args :
       {std::string("/nonexistent.log 0 1"), kIntel + " -1 1", kIntel + " 0 1 --method ndt", kIntel + " 0 1 --guess 1,2"}) {
    const CliResult r = runCli("align " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
  }
  if (!std::filesystem::exists(kIntel)) GTEST_SKIP() << "shared data absent: " << kIntel;
  EXPECT_EQ(runCli("align " + kIntel + " 0 99999").code, 2);
}

TEST(AlignCommand, HumanReadableOutput) {
  if (!std::filesystem::exists(kIntel)) GTEST_SKIP() << "shared data absent: " << kIntel;
  const CliResult r = runCli("align " + kIntel + " 10 12 --method icp --covariance hessian");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("transform:"), std::string::npos);
  EXPECT_NE(r.out.find("covariance (hessian"), std::string::npos);
}
