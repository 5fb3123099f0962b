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
  EXPECT_NE(r.out.find("--checkpoint-every"), std::string::npos);
  EXPECT_NE(r.out.find("--continue"), std::string::npos);
}

// A run that stops on an error (here the log's copy ends in a damaged line) keeps its last
// checkpoint; once the log is whole again, `run --continue` goes on from there and ends as one
// run over the whole log. A run that completes leaves no checkpoint, and its outputs are those of
// a run without checkpoints.
TEST(RunCheckpoint, AStoppedRunContinuesFromItsCheckpoint) {
  const fs::path dir = scratchDir("cli_checkpoint");
  const SplitLog log = splitExcerpt(dir, 2000);
  const std::string whole = (dir / "whole").string(), run = (dir / "run").string(), every = (dir / "every").string();
  ASSERT_EQ(runCli("run --quiet --ini " + kIni + " --out " + whole + " " + log.whole).code, 0);

  const std::string input = (dir / "log.clf").string();
  writeFile(input, slurp(log.first) + "FLASER 181 1.0 2.0 damaged\n");
  const CliResult stopped = runCli("run --quiet --ini " + kIni + " --checkpoint-every 30 --out " + run + " " + input);
  EXPECT_EQ(stopped.code, 2);
  ASSERT_TRUE(fs::exists(run + ".checkpoint/map.usmap")) << stopped.err;
  EXPECT_FALSE(fs::exists(run));

  writeFile(input, slurp(log.whole));
  const CliResult continued = runCli("run --ini " + kIni + " --checkpoint-every 30 --continue --out " + run + " " + input);
  ASSERT_EQ(continued.code, 0) << continued.err;
  EXPECT_NE(continued.err.find("continuing from " + run + ".checkpoint"), std::string::npos) << continued.err;
  EXPECT_FALSE(fs::exists(run + ".checkpoint"));
  const auto kw = readKeyframes(whole), kr = readKeyframes(run);
  ASSERT_EQ(kw.size(), kr.size());
  ASSERT_GT(kw.size(), 250u);
  for (size_t i = 0; i < kw.size(); ++i) {
    EXPECT_EQ(kw[i].t, kr[i].t) << i;
    EXPECT_NEAR(kw[i].x, kr[i].x, 2e-6) << i;
    EXPECT_NEAR(kw[i].y, kr[i].y, 2e-6) << i;
  }
  EXPECT_EQ(closurePairs(whole), closurePairs(run));

  ASSERT_EQ(runCli("run --quiet --ini " + kIni + " --checkpoint-every 50 --out " + every + " " + log.whole).code, 0);
  EXPECT_FALSE(fs::exists(every + ".checkpoint"));
  EXPECT_EQ(slurp(whole + "/trajectory_keyframes.tum"), slurp(every + "/trajectory_keyframes.tum"));
}

TEST(RunCheckpoint, ContinuingWhatCannotBeContinuedExitsTwo) {
  const fs::path dir = scratchDir("cli_checkpoint_bad");
  const SplitLog log = splitExcerpt(dir, 300);
  const std::string out = (dir / "out").string();
  const CliResult none = runCli("run --quiet --continue --out " + out + " " + log.first);
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find(out + ".checkpoint"), std::string::npos) << none.err;
  EXPECT_EQ(runCli("run --quiet --continue --resume " + out + " --out " + out + " " + log.first).code, 2);
  const CliResult negative = runCli("run --quiet --checkpoint-every -5 --out " + out + " " + log.first);
  EXPECT_EQ(negative.code, 2);
  EXPECT_NE(negative.err.find("--checkpoint-every"), std::string::npos) << negative.err;

  // A checkpoint of another log: refused, naming both.
  writeFile(dir / "first.clf", slurp(log.first) + "FLASER 181 1.0 2.0 damaged\n");
  ASSERT_EQ(runCli("run --quiet --ini " + kIni + " --checkpoint-every 5 --out " + out + " " + (dir / "first.clf").string()).code, 2);
  ASSERT_TRUE(fs::exists(out + ".checkpoint"));
  const CliResult other = runCli("run --quiet --ini " + kIni + " --continue --out " + out + " " + log.rest);
  EXPECT_EQ(other.code, 2);
  EXPECT_NE(other.err.find("rest.clf"), std::string::npos) << other.err;
}
