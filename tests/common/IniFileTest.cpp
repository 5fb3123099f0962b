#include <gtest/gtest.h>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/IniFile.h"

using urbanslam::common::ConfigError;
using urbanslam::common::IniFile;

TEST(IniFile, ParsesSectionsKeysAndAllCommentStyles) {
  const auto ini = IniFile::parse(
      "; leading comment\n# hash comment\n// slash comment\n[a]\nx = 1   // trailing\n"
      "y=two ; trailing semicolon\n\n[b]\n  z =  3.5  \n",
      "t.ini");
  ASSERT_EQ(ini.entries().size(), 3u);
  EXPECT_EQ(ini.entries()[0].section, "a");
  EXPECT_EQ(ini.entries()[0].key, "x");
  EXPECT_EQ(ini.entries()[0].value, "1");
  EXPECT_EQ(ini.entries()[1].value, "two");
  EXPECT_EQ(ini.entries()[2].section, "b");
  EXPECT_EQ(ini.entries()[2].value, "3.5");
  EXPECT_EQ(ini.entries()[2].line, 9);
}

TEST(IniFile, RejectsMalformedLinesWithFileAndLine) {
  try {
    IniFile::parse("[a]\nnot a key value\n", "bad.ini");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ini:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(IniFile::parse("x = 1\n", "t.ini"), ConfigError);          // outside a section
  EXPECT_THROW(IniFile::parse("[a]\nx=1\nx=2\n", "t.ini"), ConfigError);  // duplicate key
  EXPECT_THROW(IniFile::parse("[a\nx=1\n", "t.ini"), ConfigError);        // broken header
  EXPECT_THROW(IniFile::load("/nonexistent/file.ini"), ConfigError);
}

// An ifstream reads a directory as an empty file: that must not pass as an ini of defaults.
TEST(IniFile, ADirectoryIsNotAnIni) {
  try {
    IniFile::load(URBANSLAM_SOURCE_DIR "/ini");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/ini: is a directory"), std::string::npos) << e.what();
  }
}
