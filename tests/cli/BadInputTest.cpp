// Each bad input gives exit code 2 and one clear line naming the file (or key), never a crash.
#include <gtest/gtest.h>

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/serialization/CArchive.h>

#include <filesystem>
#include <fstream>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

void expectBadInput(const std::string& args, const std::string& fragment) {
  const CliResult r = runCli(args);
  EXPECT_EQ(r.code, 2) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << args << "\nstderr: " << r.err;
  EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  // One line, no stack trace.
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

}  // namespace

TEST(BadInput, MissingAndWrongFiles) {
  const fs::path d = scratchDir("bad_files");
  const std::string out = " --quiet --out " + (d / "out").string() + " ";
  expectBadInput("run" + out + "/nonexistent/file.rawlog", "/nonexistent/file.rawlog: no such file");
  expectBadInput("run" + out + writeFile(d / "notes.txt", "just some text\n"), "notes.txt: unrecognised format");
  expectBadInput("run" + out + writeFile(d / "empty.rawlog", ""), "empty.rawlog: empty file");
  std::string garbage;
  for (int i = 0; i < 5000; ++i) garbage += static_cast<char>(128 + (i * 31) % 128);
  expectBadInput("run" + out + writeFile(d / "garbage.rawlog", garbage), "garbage.rawlog");
}

TEST(BadInput, TruncatedRawlogAndCarmen) {
  const fs::path d = scratchDir("bad_trunc");
  const std::string out = " --quiet --out " + (d / "out").string() + " ";
  const std::string bytes = slurp(repoPath("rawlogs/intel.rawlog"));
  expectBadInput("run" + out + writeFile(d / "cut.rawlog", bytes.substr(0, bytes.size() / 3)), "cut.rawlog");
  expectBadInput("run" + out + writeFile(d / "cut.log", "ODOM 0 0 0 0 0 0 1.0 h 1.0\nFLASER 180 1.0 2.0\n"),
                 "cut.log:2: truncated laser line");
  expectBadInput("run" + out + writeFile(d / "nan.log", "FLASER 3 1.0 nan 2.0 0 0 0 0 0 0 5.0 h 5.0\n"), "nan.log:1");
  expectBadInput("run" + out + writeFile(d / "neg.log", "FLASER 3 1.0 -2.0 2.0 0 0 0 0 0 0 5.0 h 5.0\n"), "neg.log:1: negative range");
}

TEST(BadInput, EmptyAndNanScansInARawlog) {
  const fs::path d = scratchDir("bad_scans");
  const auto writeRawlog = [&](const std::string& name, size_t beams, float value) {
    const std::string path = (d / name).string();
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    mrpt::obs::CObservation2DRangeScan scan;
    scan.aperture = static_cast<float>(M_PI);
    scan.maxRange = 80;
    scan.resizeScan(beams);
    for (size_t i = 0; i < beams; ++i) {
      scan.setScanRange(i, value);
      scan.setScanRangeValidity(i, true);
    }
    arch << scan;
    return path;
  };
  const std::string out = " --quiet --out " + (d / "out").string() + " ";
  expectBadInput("run" + out + writeRawlog("empty_scan.rawlog", 0, 1.f), "empty laser scan");
  expectBadInput("run" + out + writeRawlog("nan_scan.rawlog", 10, std::nanf("")), "invalid range");
  expectBadInput("run" + out + writeRawlog("neg_scan.rawlog", 10, -1.f), "invalid range");
}

TEST(BadInput, IniAndOutputFolder) {
  const fs::path d = scratchDir("bad_ini");
  const std::string log = " " + repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  const std::string out = " --quiet --out " + (d / "out").string();
  expectBadInput("run --ini " + writeFile(d / "typo.ini", "[keyframes]\nmin_translaton_m = 1\n") + out + log,
                 "typo.ini:2: [keyframes] min_translaton_m: unknown key");
  expectBadInput("run --ini " + writeFile(d / "range.ini", "[map]\ngrid_resolution_m = -1\n") + out + log,
                 "range.ini:2: [map] grid_resolution_m: -1 is out of range");
  expectBadInput("run --ini " + (d / "missing.ini").string() + out + log, "missing.ini: cannot open");
  expectBadInput("check-ini " + writeFile(d / "section.ini", "[mapp]\nx = 1\n"), "unknown section [mapp]");
  // An output "folder" below a regular file cannot be created.
  writeFile(d / "a_file", "x");
  expectBadInput("run --quiet --out " + (d / "a_file" / "sub").string() + log, "cannot create the output folder");
}

TEST(BadInput, EvalArguments) {
  const fs::path d = scratchDir("bad_eval");
  const std::string rel = " --relations " + repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  expectBadInput("eval " + d.string(), "give --relations FILE, --reference FILE or --truth SIM_DIR");
  expectBadInput("eval " + d.string() + " --reference x.tum --truth " + d.string(), "not both");
  expectBadInput("eval " + d.string() + rel + " --max-gap -1", "--max-gap: must be a number of seconds >= 0");
  expectBadInput("eval " + (d / "no-run").string() + rel, "trajectory_odometry.tum: missing (not a run folder?)");
  // A run folder and relations that evaluate, with a --scans file that is not there.
  const fs::path run = d / "run";
  fs::create_directories(run);
  writeFile(run / "trajectory_odometry.tum", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  const std::string ok_rel = " --relations " + writeFile(d / "r.relations", "0.5 1.5 1 0 0 0 0 0\n") + " --time-offset 0";
  expectBadInput("eval " + run.string() + ok_rel + " --scans " + (d / "nowhere.tum").string(), "nowhere.tum");
  // --truth: a folder that is not a simulation's names the missing file.
  expectBadInput("eval " + run.string() + " --truth " + d.string(), "truth.tum");
}
