// `urbanslam align` on a real corrected CARMEN log (skipped without the shared data).
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <sstream>

#include "Commands.h"
#include "urbanslam/common/Error.h"

namespace urbanslam::cli {
int alignCommand(const Argv& args);
}

namespace {

const std::string kIntel = std::string(URBANSLAM_SHARED_DATA_DIR) + "/freiburg_slam_benchmark/corrected_logs/intel-corrected.log.gz";

std::string capture(const urbanslam::cli::Argv& args, int* code) {
  std::ostringstream out;
  auto* old = std::cout.rdbuf(out.rdbuf());
  try {
    *code = urbanslam::cli::alignCommand(args);
  } catch (...) {
    std::cout.rdbuf(old);
    throw;
  }
  std::cout.rdbuf(old);
  return out.str();
}

}  // namespace

TEST(AlignCommand, JsonOnConsecutiveScansMatchesReference) {
  if (!std::filesystem::exists(kIntel)) GTEST_SKIP() << "shared data absent: " << kIntel;
  int code = -1;
  const std::string out = capture({kIntel, "100", "101", "--method", "plicp", "--json"}, &code);
  EXPECT_EQ(code, 0);
  for (const char* key :
       {"\"x\":", "\"y\":", "\"phi\":", "\"cov\":[[", "\"iterations\":", "\"time_ms\":", "\"converged\":true", "\"reference\":"})
    EXPECT_NE(out.find(key), std::string::npos) << key << " in " << out;
}

TEST(AlignCommand, BadInputIsInputError) {
  int code = -1;
  EXPECT_THROW(capture({"/nonexistent.log", "0", "1"}, &code), urbanslam::common::InputError);
  EXPECT_THROW(capture({kIntel, "-1", "1"}, &code), urbanslam::common::InputError);
  EXPECT_THROW(capture({kIntel, "0", "1", "--method", "ndt"}, &code), urbanslam::common::InputError);
  EXPECT_THROW(capture({kIntel, "0", "1", "--guess", "1,2"}, &code), urbanslam::common::InputError);
  if (!std::filesystem::exists(kIntel)) GTEST_SKIP() << "shared data absent: " << kIntel;
  EXPECT_THROW(capture({kIntel, "0", "99999"}, &code), urbanslam::common::InputError);
}

TEST(AlignCommand, HumanReadableOutput) {
  if (!std::filesystem::exists(kIntel)) GTEST_SKIP() << "shared data absent: " << kIntel;
  int code = -1;
  const std::string out = capture({kIntel, "10", "12", "--method", "icp", "--covariance", "hessian"}, &code);
  EXPECT_EQ(code, 0);
  EXPECT_NE(out.find("transform:"), std::string::npos);
  EXPECT_NE(out.find("covariance (hessian"), std::string::npos);
}
