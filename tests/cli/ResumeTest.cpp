// `urbanslam run --resume`: a run over the first part of a log, continued with the rest by a
// second run, ends as one run over the whole log; a map that is not sound is refused with exit 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

const std::string kIni = repoPath("ini/fr079.ini");

// The Freiburg 079 excerpt as a whole and split after `first` measurement lines; both parts
// keep the header and PARAM lines (the sensor description), as a log split by hand would.
struct SplitLog {
  std::string whole, first, rest;
};

SplitLog splitExcerpt(const fs::path& dir, size_t first) {
  std::istringstream in(gunzip(repoPath("rawlogs/fr079-raw-excerpt.clf.gz")));
  std::string header, a, b, line;
  size_t measurements = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("PARAM", 0) == 0) {
      header += line + "\n";
    } else {
      (measurements++ < first ? a : b) += line + "\n";
    }
  }
  return {writeFile(dir / "whole.clf", header + a + b), writeFile(dir / "first.clf", header + a), writeFile(dir / "rest.clf", header + b)};
}

struct TumRow {
  double t, x, y, phi;
};

std::vector<TumRow> readKeyframes(const fs::path& run) {
  std::ifstream in(run / "trajectory_keyframes.tum");
  std::vector<TumRow> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double t, x, y, z, qx, qy, qz, qw;
    ss >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    rows.push_back({t, x, y, 2 * std::atan2(qz, qw)});
  }
  return rows;
}

// loop_closures.csv without the columns that print computed numbers: which pairs, and their fate.
std::vector<std::string> closurePairs(const fs::path& run) {
  std::ifstream in(run / "loop_closures.csv");
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string from, to, from_time, to_time, detector, score, accepted, reason;
    std::getline(ss, from, ',');
    std::getline(ss, to, ',');
    std::getline(ss, from_time, ',');
    std::getline(ss, to_time, ',');
    std::getline(ss, detector, ',');
    std::getline(ss, score, ',');
    std::getline(ss, accepted, ',');
    std::getline(ss, reason, ',');
    rows.push_back(from + "," + to + "," + accepted + "," + reason);
  }
  return rows;
}

}  // namespace

TEST(RunResume, ContinuedRunEqualsTheWholeRun) {
  const fs::path dir = scratchDir("cli_resume");
  const SplitLog log = splitExcerpt(dir, 2000);
  const std::string whole = (dir / "whole").string(), first = (dir / "first").string(), rest = (dir / "rest").string();

  ASSERT_EQ(runCli("run --quiet --ini " + kIni + " --out " + whole + " " + log.whole).code, 0);
  const CliResult a = runCli("run --quiet --ini " + kIni + " --out " + first + " " + log.first);
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_TRUE(fs::exists(fs::path(first) / "map.usmap"));
  // The run folder names the map; without --ini the map's own options are used.
  const CliResult b = runCli("run --quiet --out " + rest + " --resume " + first + " " + log.rest);
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_NE(slurp(rest + "/stats.json").find("\"resumed_map\""), std::string::npos);

  const auto kw = readKeyframes(whole), kr = readKeyframes(rest);
  ASSERT_GT(kw.size(), readKeyframes(first).size());
  ASSERT_EQ(kw.size(), kr.size());
  for (size_t i = 0; i < kw.size(); ++i) {
    EXPECT_EQ(kw[i].t, kr[i].t) << i;
    // The TUM files print 6 decimals; the second log's odometry is re-chained by its reader from
    // its own first reading, which moves the last digits of a double, not the printed ones.
    EXPECT_NEAR(kw[i].x, kr[i].x, 2e-6) << i;
    EXPECT_NEAR(kw[i].y, kr[i].y, 2e-6) << i;
    EXPECT_NEAR(std::remainder(kw[i].phi - kr[i].phi, 2 * M_PI), 0.0, 1e-5) << i;
  }
  const auto cw = closurePairs(whole), cr = closurePairs(rest);
  EXPECT_GT(cw.size(), closurePairs(first).size());
  EXPECT_EQ(cw, cr);

  // An ini that changes an algorithm key is refused, naming it; an output key may change.
  const std::string changed = writeFile(dir / "changed.ini", slurp(kIni) + "\n[loop_closure]\nmax_candidates = 7\n");
  const CliResult c = runCli("run --quiet --ini " + changed + " --out " + (dir / "c").string() + " --resume " + first + " " + log.rest);
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("[loop_closure] max_candidates"), std::string::npos) << c.err;
  const std::string quieter = writeFile(dir / "quieter.ini", slurp(kIni) + "\n[output]\nwrite_pcd = false\n");
  EXPECT_EQ(runCli("run --quiet --ini " + quieter + " --out " + (dir / "d").string() + " --resume " + first + " " + log.rest).code, 0);
}

TEST(RunResume, CorruptMapExitsTwoNamingIt) {
  const fs::path dir = scratchDir("cli_resume_corrupt");
  const SplitLog log = splitExcerpt(dir, 300);
  ASSERT_EQ(runCli("run --quiet --ini " + kIni + " --out " + (dir / "first").string() + " " + log.first).code, 0);
  std::string bytes = slurp((dir / "first" / "map.usmap").string());
  ASSERT_GT(bytes.size(), 100u);
  bytes[bytes.size() - 10] = static_cast<char>(bytes[bytes.size() - 10] ^ 0x01);
  const std::string bad = writeFile(dir / "bad.usmap", bytes);
  const CliResult r = runCli("run --quiet --out " + (dir / "out").string() + " --resume " + bad + " " + log.rest);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("checksum"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));

  const CliResult truncated = runCli("run --quiet --out " + (dir / "out").string() + " --resume " +
                                     writeFile(dir / "short.usmap", bytes.substr(0, bytes.size() / 3)) + " " + log.rest);
  EXPECT_EQ(truncated.code, 2);
  EXPECT_NE(truncated.err.find("truncated map"), std::string::npos) << truncated.err;
  const CliResult not_map = runCli("run --quiet --out " + (dir / "out").string() + " --resume " + log.first + " " + log.rest);
  EXPECT_EQ(not_map.code, 2);
  EXPECT_NE(not_map.err.find("not an urbanslam map"), std::string::npos) << not_map.err;
  const CliResult no_log = runCli("run --quiet --resume " + (dir / "first").string());
  EXPECT_EQ(no_log.code, 2);
}

TEST(RunResume, HelpListsResume) {
  const CliResult r = runCli("run --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("--resume"), std::string::npos);
  EXPECT_NE(r.out.find("map.usmap"), std::string::npos);
}
