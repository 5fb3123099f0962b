// `urbanslam localize`: a map from the first part of a log, the rest localized in it; the
// outputs are what `urbanslam eval` scores, against the benchmark relations; bad input is one
// line and exit 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

// The FR079 excerpt split after its first `scans` laser scans.
std::pair<std::string, std::string> splitExcerpt(const fs::path& dir, size_t scans) {
  return splitCarmenLog(repoPath("rawlogs/fr079-raw-excerpt.clf.gz"), dir, scans);
}

double jsonNumber(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\":(-?[0-9.eE+-]+)"))) return -1;
  return std::stod(m[1]);
}

}  // namespace

TEST(LocalizeCommand, LocalizesTheRestOfALogInTheMapOfItsFirstPart) {
  const fs::path dir = scratchDir("localize_cli");
  const auto [first, rest] = splitExcerpt(dir, 600);
  const CliResult run = runCli("run --quiet --ini " + repoPath("ini/fr079.ini") + " --out " + (dir / "map").string() + " " + first);
  ASSERT_EQ(run.code, 0) << run.err;
  const CliResult loc = runCli("localize --quiet --json --map " + (dir / "map").string() + " --out " + (dir / "loc").string() + " " + rest);
  ASSERT_EQ(loc.code, 0) << loc.err;
  for (const char* f : {"trajectory_scans.tum", "trajectory_online.tum", "localization.csv", "stats.json"})
    EXPECT_TRUE(fs::exists(dir / "loc" / f)) << f;
  // The smoothed trajectory and the online one hold the same scans at different poses.
  EXPECT_NE(loc.out.find("\"smoothed\":true"), std::string::npos);
  const std::string smoothed = slurp((dir / "loc" / "trajectory_scans.tum").string());
  const std::string online = slurp((dir / "loc" / "trajectory_online.tum").string());
  EXPECT_EQ(std::count(smoothed.begin(), smoothed.end(), '\n'), std::count(online.begin(), online.end(), '\n'));
  EXPECT_NE(smoothed, online);
  EXPECT_EQ(jsonNumber(loc.out, "scans_used"), 600);
  EXPECT_GT(jsonNumber(loc.out, "tracking"), 200);
  EXPECT_GE(jsonNumber(loc.out, "first_fix_s"), 0);
  EXPECT_LE(jsonNumber(loc.out, "first_fix_s"), 3);
  // Every scan has a row; the header names the columns.
  const std::string csv = slurp((dir / "loc" / "localization.csv").string());
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 601);
  EXPECT_EQ(csv.rfind("time,x,y,phi,cov_xx,cov_xy,cov_xphi,cov_yy,cov_yphi,cov_phiphi,state", 0), 0u);

  // eval scores the folder as it scores a run: the tracked scans against the relations.
  const CliResult eval = runCli("eval " + (dir / "loc").string() + " --json --time-offset 0 --max-gap 1 --relations " +
                                repoPath("rawlogs/fr079-raw-excerpt.relations"));
  ASSERT_EQ(eval.code, 0) << eval.err;
  EXPECT_GT(jsonNumber(eval.out, "used"), 40);
  EXPECT_LT(jsonNumber(eval.out, "abs_trans_mean_m"), 0.06);

  // A second localization may replace the first's folder; a user's folder is never replaced.
  // --no-smoothing writes the online poses as the trajectory.
  EXPECT_EQ(
      runCli("localize --quiet --no-smoothing --map " + (dir / "map").string() + " --out " + (dir / "loc").string() + " " + rest).code, 0);
  EXPECT_EQ(slurp((dir / "loc" / "trajectory_scans.tum").string()), slurp((dir / "loc" / "trajectory_online.tum").string()));
  fs::create_directories(dir / "mine");
  writeFile(dir / "mine" / "notes.txt", "keep");
  EXPECT_EQ(runCli("localize --quiet --map " + (dir / "map").string() + " --out " + (dir / "mine").string() + " " + rest).code, 2);
  EXPECT_TRUE(fs::exists(dir / "mine" / "notes.txt"));
}

TEST(LocalizeCommand, BadInputIsOneLineAndExitTwo) {
  const fs::path dir = scratchDir("localize_bad");
  const std::string log = repoPath("rawlogs/fr079-raw-excerpt.clf.gz");
  const std::string not_a_map = writeFile(dir / "map.usmap", "not a map");
  const auto expectBad = [](const CliResult& r, const std::string& names) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
  };
  expectBad(runCli("localize " + log), "--map");
  expectBad(runCli("localize --map " + not_a_map + " " + log), not_a_map);
  expectBad(runCli("localize --map " + not_a_map + " --initial 1,2 " + log), "--initial");
  expectBad(runCli("localize --map " + (dir / "missing").string() + " " + log), (dir / "missing").string());
  const CliResult help = runCli("localize --help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("--initial"), std::string::npos);
}
