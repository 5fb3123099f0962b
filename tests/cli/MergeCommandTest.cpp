// `urbanslam merge` and `urbanslam run --map`: the two halves of a log, each mapped in its own
// frame, joined into one map; a map of another building is not joined but kept as a separate
// map; bad input is one line and exit 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <sstream>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

double jsonNumber(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\":(-?[0-9.eE+-]+)"))) return -1;
  return std::stod(m[1]);
}

std::string runFr079(const fs::path& out, const std::string& log) {
  return "run --quiet --ini " + repoPath("ini/fr079.ini") + " --out " + out.string() + " " + log;
}

}  // namespace

TEST(MergeCommand, JoinsTheMapsOfTwoHalvesOfALog) {
  const fs::path dir = scratchDir("merge_cli");
  const auto [first, rest] = splitCarmenLog(repoPath("rawlogs/fr079-raw-excerpt.clf.gz"), dir, 600);
  ASSERT_EQ(runCli(runFr079(dir / "a", first)).code, 0);
  ASSERT_EQ(runCli(runFr079(dir / "b", rest)).code, 0);
  const CliResult merged =
      runCli("merge --quiet --json " + (dir / "a").string() + " " + (dir / "b").string() + " --out " + (dir / "m").string());
  ASSERT_EQ(merged.code, 0) << merged.err;
  EXPECT_NE(merged.out.find("\"sessions\":[{"), std::string::npos);
  EXPECT_NE(merged.out.find("\"joined\":true"), std::string::npos);
  EXPECT_GE(jsonNumber(merged.out, "scans_agreeing"), 4);
  for (const char* f : {"map.usmap", "trajectory_scans.tum", "grid.png", "pose_graph.g2o", "stats.json"})
    EXPECT_TRUE(fs::exists(dir / "m" / f)) << f;

  // Every relation of the log, across the two halves too, is scored on the merged map.
  const std::string relations = repoPath("rawlogs/fr079-raw-excerpt.relations");
  const CliResult eval = runCli("eval " + (dir / "m").string() + " --json --relations " + relations);
  ASSERT_EQ(eval.code, 0) << eval.err;
  EXPECT_EQ(jsonNumber(eval.out, "used"), 287);
  EXPECT_LT(jsonNumber(eval.out, "abs_trans_mean_m"), 0.06);

  // The second half mapped into the first half's map from an unknown start.
  const CliResult mapped = runCli("run --quiet --json --map " + (dir / "a").string() + " --out " + (dir / "r").string() + " " + rest);
  ASSERT_EQ(mapped.code, 0) << mapped.err;
  EXPECT_NE(mapped.out.find("\"joined\":true"), std::string::npos);
  EXPECT_GT(jsonNumber(mapped.out, "joined_at_s"), 1339);
  const CliResult eval_mapped = runCli("eval " + (dir / "r").string() + " --json --relations " + relations);
  EXPECT_EQ(jsonNumber(eval_mapped.out, "used"), 287);

  // The merged map is a map like any run's: the second half's first 100 scans localize in it.
  std::istringstream in(slurp(rest));
  std::string line, head;
  for (int scans = 0; scans < 100 && std::getline(in, line);) {
    scans += line.rfind("FLASER", 0) == 0;
    head += line + "\n";
  }
  const std::string few = writeFile(dir / "few.clf", head);
  const CliResult loc = runCli("localize --quiet --json --map " + (dir / "m").string() + " --out " + (dir / "loc").string() + " " + few);
  EXPECT_EQ(loc.code, 0) << loc.err;
  EXPECT_GT(jsonNumber(loc.out, "tracking"), 40);

  // A map of another building is not found in it: it stays a separate map in the merged file,
  // and the outputs are the first map's.
  ASSERT_EQ(runCli("run --quiet --out " + (dir / "intel").string() + " --ini " + repoPath("ini/fr079.ini") + " " +
                   repoPath("rawlogs/intel-corrected-excerpt.log.gz"))
                .code,
            0);
  const CliResult other =
      runCli("merge --json " + (dir / "a").string() + " " + (dir / "intel").string() + " --out " + (dir / "x").string());
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_NE(other.err.find("was not found in the other maps: kept as separate map 1"), std::string::npos) << other.err;
  EXPECT_NE(other.out.find("\"separate_map\":1"), std::string::npos) << other.out;
  EXPECT_NE(other.out.find("\"separate_maps\":[{\"keyframes\":"), std::string::npos) << other.out;
  // The separate map is a map to localize in, in its own frame: the Intel excerpt tracks in it
  // with no initial pose; the first map does not hold it; there is no second separate map.
  const std::string intel = repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  const CliResult in_separate =
      runCli("localize --quiet --json --map " + (dir / "x").string() + " --separate-map 1 --out " + (dir / "lx").string() + " " + intel);
  ASSERT_EQ(in_separate.code, 0) << in_separate.err;
  EXPECT_NE(in_separate.out.find("\"separate_map\":1"), std::string::npos) << in_separate.out;
  EXPECT_GT(jsonNumber(in_separate.out, "tracking_fraction"), 0.8) << in_separate.out;
  const CliResult in_first =
      runCli("localize --quiet --json --map " + (dir / "x").string() + " --separate-map 0 --out " + (dir / "l0").string() + " " + intel);
  ASSERT_EQ(in_first.code, 0) << in_first.err;
  EXPECT_LT(jsonNumber(in_first.out, "tracking_fraction"), 0.2) << in_first.out;
  // With no map named, the log is searched for in both: the separate map holds it, and tracks it
  // as when named (the same scans: the first map never found its place to take them).
  const CliResult searched = runCli("localize --json --map " + (dir / "x").string() + " --out " + (dir / "la").string() + " " + intel);
  ASSERT_EQ(searched.code, 0) << searched.err;
  EXPECT_NE(searched.out.find("\"separate_map\":1"), std::string::npos) << searched.out;
  EXPECT_NE(searched.out.find("\"maps_searched\":2"), std::string::npos) << searched.out;
  EXPECT_EQ(jsonNumber(searched.out, "tracking"), jsonNumber(in_separate.out, "tracking")) << searched.out;
  EXPECT_EQ(slurp(dir / "la" / "trajectory_scans.tum"), slurp(dir / "lx" / "trajectory_scans.tum"));
  EXPECT_NE(searched.err.find("searched in the file's 2 maps, separate map 1 went on"), std::string::npos) << searched.err;
  const CliResult no_such = runCli("localize --map " + (dir / "x").string() + " --separate-map 2 " + intel);
  EXPECT_EQ(no_such.code, 2);
  EXPECT_NE(no_such.err.find("--separate-map 2: " + (dir / "x" / "map.usmap").string() + " holds 1 separate map"), std::string::npos)
      << no_such.err;
  // A log mapped into a map it is not found in: its own map comes first (a resumed run continues
  // it), the map it was not found in is kept as a separate one.
  const CliResult unjoined = runCli("run --json --map " + (dir / "intel").string() + " --out " + (dir / "u").string() + " " + few);
  ASSERT_EQ(unjoined.code, 0) << unjoined.err;
  EXPECT_NE(unjoined.err.find("its map is its own"), std::string::npos) << unjoined.err;
  EXPECT_NE(unjoined.out.find("\"separate_maps\":[{\"keyframes\":"), std::string::npos) << unjoined.out;
  EXPECT_NE(unjoined.out.find("\"sessions\":[\"" + (dir / "intel").string()), std::string::npos) << unjoined.out;
  // Resumed, the separate map is carried along.
  const CliResult resumed = runCli("run --quiet --json --resume " + (dir / "x").string() + " --out " + (dir / "xr").string() + " " + few);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("\"separate_maps\":[{\"keyframes\":"), std::string::npos) << resumed.out;
}

TEST(MergeCommand, BadInputIsOneLineAndExitTwo) {
  const fs::path dir = scratchDir("merge_bad");
  const auto [first, rest] = splitCarmenLog(repoPath("rawlogs/fr079-raw-excerpt.clf.gz"), dir, 100);
  ASSERT_EQ(runCli(runFr079(dir / "a", first)).code, 0);
  // Another configuration: the default ini's [input] differs from fr079.ini's.
  ASSERT_EQ(runCli("run --quiet --out " + (dir / "d").string() + " " + first).code, 0);
  const std::string not_a_map = writeFile(dir / "map.usmap", "not a map");
  const auto expectBad = [](const CliResult& r, const std::string& names) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << r.err;
  };
  expectBad(runCli("merge " + (dir / "a").string()), "MAPS");
  expectBad(runCli("merge " + (dir / "a").string() + " " + not_a_map), not_a_map);
  expectBad(runCli("merge " + (dir / "a").string() + " " + (dir / "d").string()), "[input]");
  expectBad(runCli("run --map " + (dir / "a").string() + " --resume " + (dir / "a").string() + " " + rest), "not both");
  expectBad(runCli("run --map " + not_a_map + " " + rest), not_a_map);
  const CliResult help = runCli("merge --help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("place recognition"), std::string::npos);
}
