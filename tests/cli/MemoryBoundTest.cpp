// The memory bound of the README (Limits): every command, on the shipped inputs and on corrupt
// ones, ends with exit code 0 or 2 and a peak RSS under 1 GB, run under an address-space limit
// so that a runaway allocation fails here instead of swapping the machine.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

// The documented bound, and the address space the commands run in (the bound plus room for the
// shared libraries' and threads' mappings, which count in the address space but not the RSS).
constexpr double kPeakRssBoundMb = 1024;
constexpr rlim_t kAddressSpaceBytes = rlim_t(2560) << 20;

// AddressSanitizer reserves terabytes of address space and keeps freed memory in quarantine:
// under it only the exit codes are checked.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

struct Bounded {
  int code = -1;       // exit code, or -signal
  double peak_mb = 0;  // peak RSS of the command
  std::string err;
};

Bounded runBounded(const std::vector<std::string>& args) {
  const fs::path err_path = scratchDir("memory_bound") / ("err_" + std::to_string(::getpid()) + ".txt");
  std::vector<std::string> argv_s{URBANSLAM_CLI};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    if (!kSanitized) {
      const rlimit limit{kAddressSpaceBytes, kAddressSpaceBytes};
      setrlimit(RLIMIT_AS, &limit);
    }
    const int null_fd = open("/dev/null", O_RDWR);
    const int err_fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(null_fd, 0);
    dup2(null_fd, 1);
    dup2(err_fd, 2);
    execv(argv[0], argv.data());
    _exit(127);
  }
  Bounded r;
  int status = 0;
  rusage usage{};
  if (pid < 0 || wait4(pid, &status, 0, &usage) != pid) return r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  r.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;
  r.err = slurp(err_path.string());
  fs::remove(err_path);
  return r;
}

std::string describe(const std::vector<std::string>& args) {
  std::string s = "urbanslam";
  for (const auto& a : args) s += " " + a;
  return s;
}

// Exit code 0 or 2 (2: one line on stderr), peak RSS under the bound.
void expectBounded(const std::vector<std::string>& args, int expected_code = -1) {
  const Bounded r = runBounded(args);
  const std::string what = describe(args) + "\nstderr: " + r.err;
  EXPECT_TRUE(r.code == 0 || r.code == 2) << "exit " << r.code << ": " << what;
  if (expected_code >= 0) EXPECT_EQ(r.code, expected_code) << what;
  if (r.code == 2) EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what;
  if (!kSanitized) EXPECT_LT(r.peak_mb, kPeakRssBoundMb) << what;
  EXPECT_GT(r.peak_mb, 0) << what;
}

// A CARMEN log of six identical scans whose odometry jumps `jump_m` along both axes halfway:
// a map kilometres across with almost nothing in it.
std::string jumpingLog(double jump_m) {
  std::ostringstream o;
  std::string ranges;
  for (int i = 0; i < 180; ++i) ranges += " 5.0";
  double t = 1;
  for (double x : {0.0, 0.1, 0.2, jump_m, jump_m + 0.1, jump_m + 0.2}) {
    o << "ODOM " << x << " " << x << " 0 0 0 0 " << t << " host " << t << "\n";
    t += 0.1;
    o << "FLASER 180" << ranges << " " << x << " " << x << " 0 " << x << " " << x << " 0 " << t << " host " << t << "\n";
    t += 0.1;
  }
  return o.str();
}

}  // namespace

TEST(MemoryBound, ShippedInputsEveryCommand) {
  const auto d = scratchDir("memory_bound_shipped");
  const std::string intel = repoPath("rawlogs/intel.rawlog");
  const std::string run = (d / "intel").string();
  expectBounded({"run", intel, "--out", run, "--quiet"}, 0);
  expectBounded({"run", repoPath("rawlogs/fr079-raw-excerpt.clf.gz"), "--out", (d / "fr079").string(), "--quiet"}, 0);
  expectBounded({"run", repoPath("rawlogs/victoria-park-excerpt"), "--out", (d / "vp").string(), "--quiet"}, 0);
  expectBounded({"run", repoPath("rawlogs/rtabmap-loop-excerpt"), "--out", (d / "images").string(), "--quiet"}, 0);
  expectBounded({"convert", repoPath("rawlogs/intel-corrected-excerpt.log.gz"), (d / "c.rawlog").string(), "--quiet"}, 0);
  expectBounded({"convert", repoPath("rawlogs/victoria-park-excerpt"), (d / "vp.rawlog").string(), "--quiet"}, 0);
  expectBounded({"eval", run, "--reference", run + "/reference.tum"}, 0);
  expectBounded({"eval", (d / "fr079").string(), "--relations", repoPath("rawlogs/fr079-raw-excerpt.relations")}, 0);
  expectBounded({"align", intel, "10", "11"}, 0);
  expectBounded({"graph", "/usr/share/mrpt/datasets/graph_2d_circle_50nodes.graph"}, 0);
  for (const auto& ini : fs::directory_iterator(repoPath("ini"))) expectBounded({"check-ini", ini.path().string()}, 0);
  expectBounded({"train-laser-loop", intel, "--out", (d / "m.model").string(), "--quiet"}, 0);
  expectBounded({"eval-laser-loop", repoPath("share/laser_loop/default.model"), intel, "--quiet"}, 0);
  expectBounded({"build-vocabulary", repoPath("rawlogs/rtabmap-loop-excerpt/1.jpg"), "--out", (d / "v.usvoc").string(), "--descriptor",
                 "orb", "--k", "3", "--levels", "2", "--quiet"},
                0);
  expectBounded({"eval-image-loop", repoPath("share/vision_loop/orb_k10_L4.usvoc"), repoPath("rawlogs/rtabmap-loop-excerpt"), "--gt",
                 repoPath("rawlogs/rtabmap-loop-excerpt/ground_truth_loops.txt"), "--quiet"},
                0);
  const std::string sim_ini = writeFile(d / "sim.ini", "[city]\narea_km2 = 0.1\n[route]\nroute_length_km = 0.3\n");
  expectBounded({"simulate", "--ini", sim_ini, "--out", (d / "sim").string(), "--quiet"}, 0);
  expectBounded({"run", (d / "sim/city.rawlog").string(), "--out", (d / "sim_run").string(), "--quiet"}, 0);
  expectBounded({"eval", (d / "sim_run").string(), "--truth", (d / "sim").string()}, 0);
}

TEST(MemoryBound, CorruptInputs) {
  const auto d = scratchDir("memory_bound_corrupt");
  // A rawlog scan that declares 2^31 - 1 beams.
  std::string raw = gunzip(repoPath("rawlogs/intel.rawlog"));
  size_t at = 0;
  for (int k = 0; k < 6; ++k) at = raw.find("CObservation2DRangeScan", at + 1);
  const uint32_t beams180 = 180, huge = 0x7fffffff;
  const size_t count = raw.find(std::string(reinterpret_cast<const char*>(&beams180), 4), at);
  ASSERT_LT(count - at, 400u);
  std::memcpy(&raw[count], &huge, 4);
  const std::string beams = writeFile(d / "beams.rawlog", raw);
  expectBounded({"run", beams, "--out", (d / "beams").string(), "--quiet"}, 2);
  expectBounded({"convert", beams, (d / "beams_out.rawlog").string(), "--quiet"}, 2);
  expectBounded({"align", beams, "10", "11"}, 2);
  // The same file cut in half.
  const std::string cut = writeFile(d / "cut.rawlog", raw.substr(0, raw.size() / 2));
  expectBounded({"run", cut, "--out", (d / "cut").string(), "--quiet"}, 2);
  // A CARMEN line declaring two billion beams.
  std::string ranges;
  for (int i = 0; i < 180; ++i) ranges += " 5.0";
  const std::string count_log =
      writeFile(d / "count.log", "ODOM 0 0 0 0 0 0 1.0 h 1.0\nFLASER 2000000000" + ranges + " 0 0 0 0 0 0 1.1 h 1.1\n");
  expectBounded({"run", count_log, "--out", (d / "count").string(), "--quiet"}, 2);
  // Odometry that jumps 3 km along both axes: the occupancy grid would need 10^10 cells at
  // 5 cm; it is written coarser instead.
  const std::string jump = writeFile(d / "jump.log", jumpingLog(3000));
  expectBounded({"run", jump, "--out", (d / "jump").string(), "--quiet"}, 0);
  // Pose graphs with ids far apart (a graph is not indexed by id).
  const std::string ids = writeFile(d / "ids.g2o", "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 1 900000000000 1 0 0 1 0 0 1 0 1\n");
  expectBounded({"graph", ids});
  // A vocabulary whose header claims 2^40 nodes.
  std::string voc = slurp(repoPath("share/vision_loop/orb_k10_L4.usvoc"));
  const uint64_t nodes = uint64_t(1) << 40;
  std::memcpy(&voc[24], &nodes, 8);
  const std::string bad_voc = writeFile(d / "bad.usvoc", voc);
  expectBounded({"eval-image-loop", bad_voc, repoPath("rawlogs/rtabmap-loop-excerpt"), "--gt",
                 repoPath("rawlogs/rtabmap-loop-excerpt/ground_truth_loops.txt"), "--quiet"},
                2);
  // A TUM reference with one absurd line.
  const std::string tum = writeFile(d / "ref.tum", "1 0 0 0 0 0 0 1\n1e300 0 0 0 0 0 0 1\n");
  expectBounded({"eval", (d / "jump").string(), "--reference", tum});
}

TEST(MemoryBound, OccupancyGridOfAHugeMapIsCoarsened) {
  const auto d = scratchDir("memory_bound_grid");
  const std::string jump = writeFile(d / "jump.log", jumpingLog(3000));
  const Bounded r = runBounded({"run", jump, "--out", (d / "out").string(), "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string stats = slurp((d / "out/stats.json").string());
  const auto at = stats.find("\"resolution_m\"", stats.find("\"grid\""));
  ASSERT_NE(at, std::string::npos) << stats;
  // 3 km x 3 km in at most 10^8 cells: cells of at least 0.3 m.
  EXPECT_GT(std::stod(stats.substr(stats.find(':', at) + 1)), 0.29);
  EXPECT_NE(slurp((d / "out/grid.yaml").string()).find("resolution: 0.3"), std::string::npos);
}
