// Corrupt copies of the shipped logs, made here: a bad count, number or value gives exit code 2
// and one line naming the file (and entry or line), in bounded memory and time.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

// Address space for the executable under test: far more than a sane run needs, far less than
// what a corrupt count asks for. AddressSanitizer cannot start under such a limit (it reserves
// terabytes for its shadow memory), and its allocator keeps freed memory: under it only the
// errors are checked.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
constexpr const char* kMemoryLimit = "";
#else
constexpr bool kSanitized = false;
constexpr const char* kMemoryLimit = "ulimit -v 1500000; ";
#endif

void expectOneLineError(const CliResult& r, const std::string& fragment, const std::string& what) {
  EXPECT_EQ(r.code, 2) << what << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << what << "\nstderr: " << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_EQ(r.err.find("===="), std::string::npos) << r.err;
}

void expectBadInput(const std::string& args, const std::string& fragment) { expectOneLineError(runCli(args), fragment, args); }

// The Intel rawlog with the beam count of its 6th scan replaced.
std::string withBeamCount(uint32_t beams) {
  std::string raw = gunzip(repoPath("rawlogs/intel.rawlog"));
  size_t at = 0;
  for (int k = 0; k < 6; ++k) at = raw.find("CObservation2DRangeScan", at + 1);
  const uint32_t beams180 = 180;
  const size_t count = raw.find(std::string(reinterpret_cast<const char*>(&beams180), 4), at);
  EXPECT_LT(count - at, 400u);
  std::memcpy(&raw[count], &beams, 4);
  return raw;
}

double childPeakRssMb() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// Replaces field `field` of the `nth` line starting with `tag`.
std::string withField(const std::string& text, const std::string& tag, int nth, size_t field, const std::string& value) {
  std::istringstream in(text);
  std::string line, out;
  int seen = 0;
  while (std::getline(in, line)) {
    if (line.rfind(tag + " ", 0) == 0 && ++seen == nth) {
      std::istringstream f(line);
      std::vector<std::string> v;
      for (std::string w; f >> w;) v.push_back(w);
      v.at(field) = value;
      line.clear();
      for (const auto& w : v) line += (line.empty() ? "" : " ") + w;
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace

// MRPT allocates (and zero-fills) what a scan's beam count declares before reading the beams:
// 2^32 beams segfaulted, 2^26 took 660 MB, before these were bounded.
TEST(CorruptInput, RawlogCountsAreBoundedBeforeAllocation) {
  const fs::path d = scratchDir("corrupt_rawlog");
  const std::string out = " --quiet --out " + (d / "out").string() + " ";
  for (const uint32_t beams : {0xffffffffu, 0x7fffffffu, 0x04000000u}) {
    const std::string raw = withBeamCount(beams);
    for (const bool gz : {false, true}) {
      const std::string name = "beams_" + std::to_string(beams) + (gz ? ".rawlog.gz" : ".rawlog");
      const std::string path = gz ? writeGz(d / name, raw) : writeFile(d / name, raw);
      expectOneLineError(runCliAfter(kMemoryLimit, "run" + out + path),
                         name + ": entry 227: corrupt rawlog: its mrpt::obs::CObservation2DRangeScan declares a block of", name);
      expectOneLineError(runCliAfter(kMemoryLimit, "convert --quiet " + path + " " + (d / "c.rawlog").string()), name + ": entry 227",
                         name);
    }
  }
  if (!kSanitized) EXPECT_LT(childPeakRssMb(), 300.0);
}

// MRPT's messages are a banner and a backtrace: the error shows the innermost cause.
TEST(CorruptInput, MrptErrorsShowTheirCause) {
  const fs::path d = scratchDir("corrupt_mrpt_message");
  std::string raw = gunzip(repoPath("rawlogs/intel.rawlog"));
  const size_t at = raw.find("CObservation2DRangeScan", 100000);
  raw[at + std::strlen("CObservation2DRangeScan")] = 99;  // the serialization version byte
  expectBadInput("run --quiet --out " + (d / "out").string() + " " + writeFile(d / "version.rawlog", raw),
                 "version.rawlog: entry 629: corrupt or truncated rawlog (its mrpt::obs::CObservation2DRangeScan: Cannot parse object: "
                 "unknown serialization version number: '99')");
}

// strtod took hexadecimal and values that broke the filter far from their line; an ODOM y of
// -2^31 made the spatial index spin forever.
TEST(CorruptInput, TextLogNumbersAreStrictAndBounded) {
  const fs::path d = scratchDir("corrupt_text");
  const std::string out = " --quiet --out " + (d / "out").string() + " ";
  const std::string log = gunzip(repoPath("rawlogs/intel-corrected-excerpt.log.gz"));
  // Line 24 is the 20th ODOM line of the excerpt.
  expectBadInput("run" + out + writeFile(d / "hex.log", withField(log, "ODOM", 20, 1, "0x7fffffff")),
                 "hex.log:24: x '0x7fffffff' is not a number");
  expectBadInput("run" + out + writeFile(d / "huge.log", withField(log, "ODOM", 20, 1, "1e308")), "huge.log:24: x 1e308 is out of range");
  expectBadInput("run" + out + writeFile(d / "far.log", withField(log, "ODOM", 20, 2, "-2147483649")),
                 "far.log:24: y -2147483649 is out of range");
  expectBadInput("run" + out + writeFile(d / "inf.log", withField(log, "ODOM", 20, 3, "inf")), "inf.log:24: theta 'inf' is not a number");
  // In range, but an odometry jump of 10^4 km leaves the filter's Lambda numerically indefinite.
  expectBadInput("run" + out + writeFile(d / "jump.log", withField(log, "ODOM", 181, 2, "-9999999")),
                 "jump.log: measurement 195 (t = 36.46 s): the filter's information matrix is not positive definite");
  // An ini value in hex.
  expectBadInput("check-ini " + writeFile(d / "hex.ini", "[map]\ngrid_resolution_m = 0x1p-3\n"),
                 "hex.ini:2: [map] grid_resolution_m: '0x1p-3' is not a number");
  // Relations (eval) in hex.
  const fs::path run = d / "run";
  fs::create_directories(run);
  writeFile(run / "trajectory_odometry.tum", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  expectBadInput("eval " + run.string() + " --time-offset 0 --relations " + writeFile(d / "r.relations", "0.5 1.5 0x1 0 0 0 0 0\n"),
                 "r.relations:1");
}

TEST(CorruptInput, PoseGraphValuesAndFilterFailuresNameFileAndEdge) {
  const fs::path d = scratchDir("corrupt_graph");
  const std::string v = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\n";
  expectBadInput("graph " + writeFile(d / "info.g2o", v + "EDGE_SE2 0 1 1 0 0 1e20 0 0 1 0 1\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\n"),
                 "info.g2o:4: information entry out of range");
  expectBadInput("graph " + writeFile(d / "meas.g2o", v + "EDGE_SE2 0 1 2147483648 0 0 1 0 0 1 0 1\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\n"),
                 "meas.g2o:4: edge measurement out of range");
  expectBadInput("graph " + writeFile(d / "hex.g2o", v + "EDGE_SE2 0 1 0x1 0 0 1 0 0 1 0 1\n"), "hex.g2o:4: malformed EDGE_SE2 line");
  expectBadInput("graph " + writeFile(d / "gap.g2o", "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n"),
                 "gap.g2o: vertex 2 has no edge to an earlier vertex");
  // Within range, but an odometry step of 10^7 m on a square loop whose closures say otherwise:
  // Lambda is no longer numerically positive definite.
  std::string g;
  for (int i = 1; i < 80; ++i)
    g += "EDGE_SE2 " + std::to_string(i - 1) + " " + std::to_string(i) + (i == 30 ? " 9999999" : " 1") + " 0 " +
         (i % 10 == 0 ? "1.5707963267948966" : "0") + " 100 0 0 100 0 1000\n";
  for (int i = 40; i < 80; ++i) g += "EDGE_SE2 " + std::to_string(i - 40) + " " + std::to_string(i) + " 0 0 0 100 0 0 100 0 1000\n";
  expectBadInput("graph " + writeFile(d / "square.g2o", g),
                 "square.g2o:84: edge 4 -> 44: the filter's information matrix is not positive definite");
}

TEST(CorruptInput, ADirectoryIsNotAnIni) {
  const fs::path d = scratchDir("corrupt_ini_dir");
  expectBadInput("check-ini " + d.string(), d.string() + ": is a directory, not an ini file");
  expectBadInput(
      "run --quiet --out " + (d / "out").string() + " --ini " + d.string() + " " + repoPath("rawlogs/intel-corrected-excerpt.log.gz"),
      d.string() + ": is a directory, not an ini file");
}

TEST(CorruptInput, NothingToMapIsAnError) {
  const fs::path d = scratchDir("corrupt_empty");
  const std::string odom_only = "ODOM 0 0 0 0 0 0 1.0 h 1.0\nODOM 0.1 0 0 0 0 0 2.0 h 2.0\n";
  expectBadInput("run --quiet --out " + (d / "out").string() + " " + writeFile(d / "odom.log", odom_only), "odom.log: no laser scans");
  EXPECT_FALSE(fs::exists(d / "out"));
  const fs::path run = d / "run";
  fs::create_directories(run);
  writeFile(run / "trajectory_odometry.tum", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n");
  expectBadInput("eval " + run.string() + " --reference " + writeFile(d / "empty.tum", "# timestamp x y z qx qy qz qw\n"),
                 "empty.tum: no poses");
  expectBadInput("eval " + run.string() + " --reference " + writeFile(d / "later.tum", "100 0 0 0 0 0 0 1\n101 1 0 0 0 0 0 1\n"),
                 "later.tum: no reference pose falls inside the run's time span");
}
