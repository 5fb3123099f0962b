// A run folder holds one run: a rerun replaces it as a whole, a run killed at any moment leaves
// the earlier complete folder or the new complete one, never a mix, and never a user's folder
// deleted.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <thread>

#include "CliRunner.h"
#include "TestFiles.h"

using namespace urbanslam::test;
namespace fs = std::filesystem;

namespace {

const std::string kLog = repoPath("rawlogs/intel-corrected-excerpt.log.gz");

std::set<std::string> names(const fs::path& d) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(d)) out.insert(e.path().filename().string());
  return out;
}

// The entries of a folder other than `keep`.
std::set<std::string> othersIn(const fs::path& d, const std::string& keep) {
  auto all = names(d);
  all.erase(keep);
  return all;
}

// The files stats.json lists, plus stats.json and config.ini: what one complete run holds.
std::set<std::string> filesOfRun(const fs::path& run) {
  const std::string stats = slurp((run / "stats.json").string());
  std::set<std::string> out{"stats.json", "config.ini"};
  const size_t files = stats.find("\"files\"");
  if (files == std::string::npos) return {};
  const size_t end = stats.find(']', files);
  for (size_t q = stats.find('"', files + 7); q < end; q = stats.find('"', q + 1)) {
    const size_t close = stats.find('"', q + 1);
    out.insert(stats.substr(q + 1, close - q - 1));
    q = close;
  }
  return out;
}

}  // namespace

TEST(RunFolder, ARerunReplacesTheWholeFolder) {
  const fs::path d = scratchDir("run_folder_rerun");
  const fs::path out = d / "out";
  const std::string xyz = writeFile(d / "xyz.ini", "[output]\nwrite_pcd = false\nwrite_xyz = true\n");
  ASSERT_EQ(runCli("run --quiet --ini " + xyz + " --out " + out.string() + " " + kLog).code, 0);
  ASSERT_TRUE(fs::exists(out / "map.xyz"));
  writeFile(out / "notes_of_that_run.txt", "belongs to the first run");
  ASSERT_EQ(runCli("run --quiet --out " + out.string() + " " + kLog).code, 0);
  EXPECT_EQ(names(out), filesOfRun(out));  // map.xyz and the notes went with the earlier run
  EXPECT_TRUE(fs::exists(out / "map.pcd"));
  EXPECT_EQ(othersIn(d, "out"), (std::set<std::string>{"xyz.ini"}));  // no staging folder left
}

TEST(RunFolder, AFolderThatIsNotARunIsNeverReplaced) {
  const fs::path d = scratchDir("run_folder_foreign");
  writeFile(d / "thesis.tex", "precious");
  const CliResult r = runCli("run --quiet --out " + d.string() + " " + kLog);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(d.string() + ": exists and is not an output folder"), std::string::npos) << r.err;
  EXPECT_EQ(names(d), (std::set<std::string>{"thesis.tex"}));
  // An empty folder is fine.
  fs::create_directories(d / "empty");
  EXPECT_EQ(runCli("run --quiet --out " + (d / "empty").string() + " " + kLog).code, 0);
}

TEST(RunFolder, TemporariesOfKilledRunsAreRemoved) {
  const fs::path d = scratchDir("run_folder_stale");
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // a process id that no longer exists
  const std::string dead = std::to_string(child);
  fs::create_directories(d / (".out.partial-" + dead));
  writeFile(d / (".out.partial-" + dead) / "map.ply", "half");
  writeFile(d / (".c.partial-" + dead + ".rawlog"), "half");
  ASSERT_EQ(runCli("run --quiet --out " + (d / "out").string() + " " + kLog).code, 0);
  ASSERT_EQ(runCli("convert --quiet " + kLog + " " + (d / "c.rawlog").string()).code, 0);
  EXPECT_EQ(names(d), (std::set<std::string>{"out", "c.rawlog"}));
}

// kill -9 at random moments of a rerun whose outputs differ from the earlier run's: the folder
// is always exactly one complete run.
TEST(RunFolder, KillAtAnyMomentLeavesOneCompleteRun) {
  const fs::path d = scratchDir("run_folder_kill");
  const fs::path out = d / "out";
  const std::string xyz = writeFile(d / "xyz.ini", "[output]\nwrite_pcd = false\nwrite_xyz = true\n");
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(runCli("run --quiet --ini " + xyz + " --out " + out.string() + " " + kLog).code, 0);
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::mt19937 rng(7);
  for (int i = 0; i < 12; ++i) {
    // Alternate the two configurations, so a mix of them would show.
    const std::string ini = i % 2 ? " --ini " + xyz : "";
    const pid_t pid = ::fork();
    if (pid == 0) {
      const std::string cmd = std::string(URBANSLAM_CLI) + " run --quiet" + ini + " --out " + out.string() + " " + kLog;
      ::execl("/bin/sh", "sh", "-c", ("exec " + cmd + " >/dev/null 2>&1").c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const double at = std::uniform_real_distribution<double>(0.5, 1.2)(rng) * run_s;
    std::this_thread::sleep_for(std::chrono::duration<double>(at));
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    ASSERT_TRUE(fs::exists(out / "stats.json")) << "after kill " << i;
    const auto files = filesOfRun(out);
    EXPECT_EQ(names(out), files) << "after kill " << i;
    EXPECT_NE(files.count("map.pcd"), files.count("map.xyz")) << "after kill " << i;
  }
  // The next run cleans up what the killed ones left beside the folder.
  ASSERT_EQ(runCli("run --quiet --out " + out.string() + " " + kLog).code, 0);
  EXPECT_EQ(othersIn(d, "out"), (std::set<std::string>{"xyz.ini"}));
}
