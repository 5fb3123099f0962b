#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "CliRunner.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/MapOutputs.h"

using namespace urbanslam::test;
namespace io = urbanslam::io;
namespace fs = std::filesystem;

TEST(Cli, EverySubcommandHasHelp) {
  const CliResult top = runCli("--help");
  EXPECT_EQ(top.code, 0);
  for (const char* cmd : {"run", "convert", "check-ini"}) {
    EXPECT_NE(top.out.find(cmd), std::string::npos) << cmd;
    const CliResult r = runCli(std::string(cmd) + " --help");
    EXPECT_EQ(r.code, 0) << cmd;
    EXPECT_EQ(r.out.rfind("usage: urbanslam " + std::string(cmd), 0), 0u) << r.out;
  }
  EXPECT_EQ(runCli("no-such-command").code, 2);
  EXPECT_EQ(runCli("run --no-such-option").code, 2);
}

TEST(Cli, EveryShippedIniLoads) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(repoPath("ini"))) {
    if (e.path().extension() != ".ini") continue;
    const CliResult r = runCli("check-ini " + e.path().string());
    EXPECT_EQ(r.code, 0) << e.path() << ": " << r.err;
    ++n;
  }
  EXPECT_GE(n, 1u);
}

// default.ini documents every key the program knows, with the built-in defaults.
TEST(Cli, DefaultIniListsEveryKey) {
  const CliResult r = runCli("check-ini " + repoPath("ini/default.ini"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string ini = slurp(repoPath("ini/default.ini"));
  std::istringstream resolved(r.out);
  std::string line;
  size_t keys = 0;
  while (std::getline(resolved, line)) {
    const auto eq = line.find(" = ");
    if (line.empty() || line[0] == '/' || line[0] == '[' || eq == std::string::npos) continue;
    const std::string key = line.substr(0, eq);
    EXPECT_NE(ini.find("\n" + key + " "), std::string::npos) << "ini/default.ini lacks " << key;
    ++keys;
  }
  EXPECT_GE(keys, 10u);
}

TEST(Cli, RunOnTheShippedRawlogWritesEveryOutput) {
  const fs::path out = scratchDir("cli_run");
  const CliResult r = runCli("run --quiet --json --out " + out.string());
  // (The shipped default input: the full Intel rawlog.)
  ASSERT_EQ(r.code, 0) << r.err;
  // --json: exactly one JSON object on stdout.
  ASSERT_FALSE(r.out.empty());
  EXPECT_EQ(r.out.front(), '{');
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1);
  EXPECT_NE(r.out.find("\"keyframes\":"), std::string::npos);
  for (const char* f : {"trajectory_keyframes.tum", "trajectory_odometry.tum", "trajectory_scans.tum", "reference.tum", "map.ply",
                        "map.pcd", "map.simplemap", "grid.png", "grid.yaml", "config.ini", "stats.json"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_FALSE(fs::exists(out / "grid_tiles"));  // grid.png holds the map at full resolution
  // No temporary files left behind, in the folder or beside it.
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
  for (const auto& e : fs::directory_iterator(out.parent_path()))
    EXPECT_NE(e.path().filename().string().rfind(".cli_run.", 0), 0u) << e.path();
  // Every TUM file is a time series (the log itself has scans out of time order).
  for (const char* f : {"trajectory_keyframes.tum", "trajectory_odometry.tum", "trajectory_scans.tum", "reference.tum"}) {
    const auto t = io::readTum((out / f).string());
    for (size_t i = 1; i < t.size(); ++i) ASSERT_LE(t[i - 1].timestamp, t[i].timestamp) << f << " line " << i + 1;
  }
  // The resolved config written beside the outputs is itself a valid ini.
  EXPECT_EQ(runCli("check-ini " + (out / "config.ini").string()).code, 0);
  for (const char* f : {"pose_graph.g2o", "loop_closures.csv"}) EXPECT_TRUE(fs::exists(out / f)) << f;
  // The scans placed by matching are every keyframe and the matched scans between them, and
  // the trajectory at odometry times passes through each one at its time.
  const auto kf = io::readTum((out / "trajectory_keyframes.tum").string());
  const auto scans = io::readTum((out / "trajectory_scans.tum").string());
  const auto odo = io::readTum((out / "trajectory_odometry.tum").string());
  EXPECT_GT(scans.size(), kf.size());
  const auto at = [](const std::vector<io::StampedPose>& t, double time) {
    return std::find_if(t.begin(), t.end(), [&](const io::StampedPose& p) { return std::abs(p.timestamp - time) < 1e-6; });
  };
  for (const auto& k : kf) {
    const auto s = at(scans, k.timestamp);
    ASSERT_NE(s, scans.end()) << k.timestamp;
    EXPECT_NEAR(s->pose.x, k.pose.x, 1e-5);
    EXPECT_NEAR(s->pose.y, k.pose.y, 1e-5);
  }
  size_t on_odometry = 0;
  for (const auto& s : scans) {
    const auto o = at(odo, s.timestamp);
    if (o == odo.end()) continue;
    ++on_odometry;
    EXPECT_NEAR(o->pose.x, s.pose.x, 1e-5) << s.timestamp;
    EXPECT_NEAR(o->pose.y, s.pose.y, 1e-5) << s.timestamp;
  }
  EXPECT_GT(on_odometry, scans.size() / 2);
}

// A map larger than grid.png may be (grid_max_cells) gets grid.png coarser, and the full
// resolution in tiles that the index lists (the tiles' cells: GridTiles.* in io_tests).
TEST(Cli, ALargeMapsGridIsAlsoWrittenInTiles) {
  const fs::path d = scratchDir("cli_tiles");
  std::ofstream(d / "t.ini") << "[map]\ngrid_resolution_m = 0.1\ngrid_max_cells = 10000\ngrid_tile_cells = 100\n";
  const CliResult r = runCli("run --quiet --out " + (d / "run").string() + " --ini " + (d / "t.ini").string() + " " +
                             repoPath("rawlogs/intel-corrected-excerpt.log.gz"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string stats = slurp(d / "run" / "stats.json");
  EXPECT_NE(stats.find("\"tiles_resolution_m\": 0.1"), std::string::npos) << stats;
  std::ifstream index(d / "run" / "grid_tiles" / "tiles.csv");
  std::string line;
  std::getline(index, line);
  int tiles = 0;
  while (std::getline(index, line)) {
    std::istringstream fields(line);
    std::string i, j, png;
    std::getline(fields, i, ',');
    std::getline(fields, j, ',');
    std::getline(fields, png, ',');
    EXPECT_EQ(png, "tile_" + i + "_" + j + ".png");
    EXPECT_TRUE(fs::exists(d / "run" / "grid_tiles" / png)) << png;
    EXPECT_TRUE(fs::exists(d / "run" / "grid_tiles" / ("tile_" + i + "_" + j + ".yaml"))) << png;
    ++tiles;
  }
  EXPECT_GT(tiles, 4);
  EXPECT_NE(stats.find("\"tiles\": " + std::to_string(tiles)), std::string::npos) << stats;
}

TEST(Cli, ConvertWritesARawlogThatRunsTheSame) {
  const fs::path d = scratchDir("cli_convert");
  const std::string rawlog = (d / "x.rawlog").string();
  const CliResult c = runCli("convert --quiet --json " + repoPath("rawlogs/intel-corrected-excerpt.log.gz") + " " + rawlog);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.out.find("\"scans\":80"), std::string::npos) << c.out;
  // Odometry only: the converter is under test, not the scan matcher, whose discrete search
  // and nearest-neighbour associations can turn a 1e-8 input difference into millimetres.
  const std::string ini = (d / "odometry.ini").string();
  std::ofstream(ini) << "[local]\nscan_matching = false\n";
  ASSERT_EQ(
      runCli("run --quiet --ini " + ini + " --out " + (d / "a").string() + " " + repoPath("rawlogs/intel-corrected-excerpt.log.gz")).code,
      0);
  ASSERT_EQ(runCli("run --quiet --ini " + ini + " --out " + (d / "b").string() + " " + rawlog).code, 0);
  // MRPT stores the sensor pose as a 3D pose (yaw through a rotation matrix): equal to ~1e-8.
  std::ifstream a(d / "a" / "trajectory_keyframes.tum"), b(d / "b" / "trajectory_keyframes.tum");
  std::string la, lb;
  size_t lines = 0;
  while (std::getline(a, la)) {
    ASSERT_TRUE(std::getline(b, lb));
    if (la[0] == '#') continue;
    std::istringstream sa(la), sb(lb);
    double va, vb;
    while (sa >> va) {
      ASSERT_TRUE(sb >> vb);
      EXPECT_NEAR(va, vb, 1e-5) << la << " vs " << lb;
    }
    ++lines;
  }
  EXPECT_FALSE(std::getline(b, lb));
  EXPECT_GT(lines, 10u);
}

// MRPT's own tool opens what `convert` writes (independent reader of the file format).
TEST(Cli, RawlogEditReadsConvertedRawlogs) {
  if (!fs::exists("/usr/bin/rawlog-edit")) GTEST_SKIP() << "rawlog-edit not installed (package mrpt-apps)";
  const fs::path d = scratchDir("cli_rawlog_edit");
  for (const char* layout : {"observations", "frames"}) {
    const std::string rawlog = (d / (std::string(layout) + ".rawlog")).string();
    ASSERT_EQ(
        runCli(std::string("convert --quiet --layout ") + layout + " " + repoPath("rawlogs/intel-corrected-excerpt.log.gz") + " " + rawlog)
            .code,
        0);
    const std::string info = (d / "info.txt").string();
    const int rc = std::system(("rawlog-edit --info -i " + rawlog + " > " + info + " 2>&1").c_str());
    const std::string text = slurp(info);
    EXPECT_EQ(rc, 0) << text;
    if (std::string(layout) == "observations") {
      EXPECT_NE(text.find("Observations format               : Yes"), std::string::npos) << text;
      EXPECT_NE(text.find("FLASER /     80"), std::string::npos) << text;
    } else {
      EXPECT_NE(text.find("Actions/SensoryFrame format       : Yes"), std::string::npos) << text;
    }
  }
}

namespace {
// The number after "key": in `json`, from `from` on (-1 when absent).
double numberAfter(const std::string& json, const std::string& key, size_t from = 0) {
  const std::string k = "\"" + key + "\":";
  const size_t at = json.find(k, from);
  return at == std::string::npos ? -1 : std::stod(json.substr(at + k.size()));
}
}  // namespace

// A simulated drive, written as a rawlog and streamed straight from the simulator: both runs
// see the same measurements, so they give the same trajectory, and it follows the simulator's
// ground truth (an independent reference: the poses the sensors were simulated from).
TEST(Cli, SimulatedDriveRunsFromFileAndStream) {
  const fs::path d = scratchDir("cli_simulate");
  const fs::path ini = d / "city.ini";
  std::ofstream(ini) << "[city]\nseed = 3\narea_km2 = 0.1\n[route]\nroute_length_km = 0.4\n";
  const CliResult s = runCli("simulate --quiet --json --ini " + ini.string() + " --out " + (d / "sim").string());
  ASSERT_EQ(s.code, 0) << s.err;
  for (const char* f : {"city.rawlog", "truth.tum", "loops.csv", "walls.csv", "walls.png", "config.ini"})
    EXPECT_TRUE(fs::exists(d / "sim" / f)) << f;
  EXPECT_EQ(runCli("check-ini " + (d / "sim" / "config.ini").string()).code, 0);
  const CliResult file = runCli("run --quiet --out " + (d / "file").string() + " " + (d / "sim" / "city.rawlog").string());
  ASSERT_EQ(file.code, 0) << file.err;
  const CliResult stream = runCli("run --quiet --out " + (d / "stream").string() + " --simulate " + ini.string());
  ASSERT_EQ(stream.code, 0) << stream.err;
  const auto truth = io::readTum((d / "sim" / "truth.tum").string());
  const auto a = io::readTum((d / "file" / "trajectory_scans.tum").string());
  const auto b = io::readTum((d / "stream" / "trajectory_scans.tum").string());
  ASSERT_EQ(a.size(), truth.size());
  ASSERT_EQ(b.size(), truth.size());
  double worst = 0, driven = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) driven += std::hypot(truth[i].pose.x - truth[i - 1].pose.x, truth[i].pose.y - truth[i - 1].pose.y);
    EXPECT_NEAR(a[i].timestamp, truth[i].timestamp, 1e-6);
    EXPECT_NEAR(a[i].pose.x, b[i].pose.x, 1e-3);
    EXPECT_NEAR(a[i].pose.y, b[i].pose.y, 1e-3);
    // The map's frame is the first scan's pose.
    const urbanslam::common::Pose2 p = urbanslam::common::compose(truth.front().pose, a[i].pose);
    worst = std::max(worst, std::hypot(p.x - truth[i].pose.x, p.y - truth[i].pose.y));
  }
  EXPECT_GT(driven, 300.0);
  // The map's error over 400 m of driving stays under 0.5 % of the distance; odometry alone, with the
  // simulator's default odometry errors (those measured on FR079's), ends over 100 m off.
  EXPECT_LT(worst, 0.005 * driven);
  EXPECT_EQ(runCli("run --quiet --out " + (d / "both").string() + " --simulate " + ini.string() + " x.rawlog").code, 2);
  // Against the simulation: the map's points lie on the true walls (most within 10 cm).
  const CliResult e = runCli("eval --json " + (d / "file").string() + " --truth " + (d / "sim").string());
  ASSERT_EQ(e.code, 0) << e.err;
  EXPECT_GT(numberAfter(e.out, "within_0_1_m"), 0.5) << e.out;
  EXPECT_NE(e.out.find("\"loops_recall\":"), std::string::npos) << e.out;  // a 400 m drive has no revisit to score
  // The exported cloud is what is scored; it left out the simulated traffic's points, so fewer of
  // its points lie far from every true wall than of all the keyframes' points (map.simplemap,
  // scored once map.ply is gone).
  EXPECT_NE(e.out.find("\"source\":\"map.ply\""), std::string::npos) << e.out;
  const double cloud_far = numberAfter(e.out, "beyond_1_m");
  ASSERT_GE(cloud_far, 0) << e.out;
  fs::remove(d / "file" / "map.ply");
  const CliResult all = runCli("eval --json " + (d / "file").string() + " --truth " + (d / "sim").string());
  ASSERT_EQ(all.code, 0) << all.err;
  EXPECT_NE(all.out.find("\"source\":\"map.simplemap\""), std::string::npos) << all.out;
  const double all_far = numberAfter(all.out, "beyond_1_m");
  ASSERT_GE(all_far, 0) << all.out;
  EXPECT_LT(cloud_far, 0.5 * all_far) << cloud_far << " vs " << all_far;
}

// The same-side figures are those of an evaluation whose positives are only the revisits within
// 90° of heading, against the same negatives (a fixed count, so both runs draw the same ones).
// The operating point at a false-alarm rate is picked among all scores, positives included, so
// the two may differ by the few positives that fall between two negatives' scores there.
TEST(Cli, EvalLaserLoopReportsSameSideRevisits) {
  const std::string common = "eval-laser-loop --quiet --json --negatives-per-positive 0 --min-negatives 5000 " +
                             repoPath("share/laser_loop/default.model") + " " + repoPath("rawlogs/intel.rawlog");
  const CliResult any = runCli(common + " --max-heading-diff 180");
  const CliResult same = runCli(common + " --max-heading-diff 90");
  ASSERT_EQ(any.code, 0) << any.err;
  ASSERT_EQ(same.code, 0) << same.err;
  const size_t at = any.out.find("\"same_side\":");
  ASSERT_NE(at, std::string::npos) << any.out;
  EXPECT_GT(numberAfter(any.out, "positives"), numberAfter(any.out, "positives", at));  // the excerpt has opposite-heading revisits
  EXPECT_EQ(numberAfter(any.out, "positives", at), numberAfter(same.out, "positives"));
  EXPECT_EQ(numberAfter(any.out, "negatives"), numberAfter(same.out, "negatives"));
  const double positives = numberAfter(same.out, "positives");
  EXPECT_NEAR(numberAfter(any.out, "detection_at_fa_0.01", at), numberAfter(same.out, "detection_at_fa_0.01"), 3 / positives);
  EXPECT_NEAR(numberAfter(any.out, "detection_at_fa_0", at), numberAfter(same.out, "detection_at_fa_0"), 3 / positives);
  EXPECT_GT(numberAfter(any.out, "detection_at_fa_0.01", at), 0.1);  // the model detects same-side revisits
}
