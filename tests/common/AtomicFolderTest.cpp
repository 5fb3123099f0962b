#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/AtomicFolder.h"
#include "TestPaths.h"
#include "urbanslam/common/Error.h"

namespace fs = std::filesystem;
using namespace urbanslam::common;

namespace {

fs::path freshDir(const char* name) { return urbanslam::test::scratchDir(name); }

void touch(const fs::path& p, const std::string& text = "x") { std::ofstream(p) << text; }

size_t entries(const fs::path& d) { return static_cast<size_t>(std::distance(fs::directory_iterator(d), fs::directory_iterator{})); }

// The id of a process that has exited (and been reaped).
long deadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

const auto always = [](const std::string&) { return true; };

}  // namespace

TEST(AtomicFolder, ReplacesTheEarlierFolderAsAWhole) {
  const fs::path d = freshDir("atomic_folder");
  const fs::path target = d / "out";
  fs::create_directories(target);
  touch(target / "old_only.txt");
  touch(target / "both.txt", "old");
  {
    AtomicFolder f(target.string(), always);
    touch(fs::path(f.stagingPath()) / "both.txt", "new");
    EXPECT_TRUE(fs::exists(target / "old_only.txt"));  // nothing changes before commit
    f.commit();
  }
  EXPECT_FALSE(fs::exists(target / "old_only.txt"));
  std::ifstream in(target / "both.txt");
  std::string s;
  in >> s;
  EXPECT_EQ(s, "new");
  EXPECT_EQ(entries(d), 1u);  // no staging or earlier folder left beside it
}

TEST(AtomicFolder, AbandonedOutputsLeaveTheEarlierFolder) {
  const fs::path d = freshDir("atomic_folder_abandon");
  const fs::path target = d / "out";
  fs::create_directories(target);
  touch(target / "old.txt");
  {
    AtomicFolder f(target.string(), always);
    touch(fs::path(f.stagingPath()) / "new.txt");
  }
  EXPECT_TRUE(fs::exists(target / "old.txt"));
  EXPECT_FALSE(fs::exists(target / "new.txt"));
  EXPECT_EQ(entries(d), 1u);
  // A new folder appears only at commit.
  {
    AtomicFolder f((d / "fresh").string(), always);
    EXPECT_FALSE(fs::exists(d / "fresh"));
    f.commit();
  }
  EXPECT_TRUE(fs::is_directory(d / "fresh"));
}

TEST(AtomicFolder, RefusesWhatItMayNotReplace) {
  const fs::path d = freshDir("atomic_folder_refuse");
  touch(d / "mine.txt");
  EXPECT_THROW(AtomicFolder(d.string(), [](const std::string&) { return false; }), InputError);
  EXPECT_TRUE(fs::exists(d / "mine.txt"));
  touch(d / "a_file");
  EXPECT_THROW(AtomicFolder((d / "a_file").string(), always), InputError);
  EXPECT_THROW(AtomicFolder((d / ".").string(), always), InputError);
}

TEST(AtomicFolder, StaleTemporariesOfKilledProcessesAreRemoved) {
  const fs::path d = freshDir("atomic_folder_stale");
  const std::string dead = std::to_string(deadPid()), alive = std::to_string(::getppid());
  fs::create_directories(d / (".out.partial-" + dead));
  touch(d / (".out.partial-" + dead) / "x");
  fs::create_directories(d / (".out.partial-" + alive));  // a run in progress elsewhere
  touch(d / (".map.partial-" + dead + ".ply"));
  touch(d / (".map.partial-" + alive + ".ply"));
  touch(d / ".other.partial-1x");  // not one of ours
  {
    AtomicFolder f((d / "out").string(), always);
    f.commit();
  }
  EXPECT_FALSE(fs::exists(d / (".out.partial-" + dead)));
  EXPECT_TRUE(fs::exists(d / (".out.partial-" + alive)));
  {
    AtomicFile f((d / "map.ply").string());
    f.commit();
  }
  EXPECT_FALSE(fs::exists(d / (".map.partial-" + dead + ".ply")));
  EXPECT_TRUE(fs::exists(d / (".map.partial-" + alive + ".ply")));
  EXPECT_TRUE(fs::exists(d / ".other.partial-1x"));
}

TEST(AtomicFolder, AFolderMovedAsideByAKilledRunIsRestored) {
  const fs::path d = freshDir("atomic_folder_aside");
  const fs::path aside = d / (".out.old-" + std::to_string(deadPid()));
  fs::create_directories(aside);
  touch(aside / "stats.json");
  AtomicFolder f((d / "out").string(), always);
  EXPECT_TRUE(fs::exists(d / "out" / "stats.json"));
  EXPECT_FALSE(fs::exists(aside));
}
