#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "urbanslam/common/AtomicFile.h"
#include "TestPaths.h"
#include "urbanslam/common/Error.h"

namespace fs = std::filesystem;
using namespace urbanslam::common;

namespace {
fs::path freshDir(const char* name) { return urbanslam::test::scratchDir(name); }
}  // namespace

TEST(AtomicFile, NothingVisibleUntilCommit) {
  const fs::path d = freshDir("atomic");
  const std::string target = (d / "out.txt").string();
  {
    AtomicFile f(target);
    f.stream() << "hello";
    EXPECT_FALSE(fs::exists(target));
    f.commit();
  }
  std::ifstream in(target);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "hello");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
}

TEST(AtomicFile, AbandonedWriteLeavesNoFile) {
  const fs::path d = freshDir("atomic_abandon");
  const std::string target = (d / "out.txt").string();
  {
    AtomicFile f(target);
    f.stream() << "partial";
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 0);
  EXPECT_THROW(writeAtomically(target, [](const std::string&) { throw std::runtime_error("boom"); }), std::runtime_error);
  EXPECT_FALSE(fs::exists(target));
  EXPECT_THROW(AtomicFile((d / "no_such_dir" / "x.txt").string()), InputError);
}
