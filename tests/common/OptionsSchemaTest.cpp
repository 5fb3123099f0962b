#include <gtest/gtest.h>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/IniFile.h"
#include "urbanslam/common/OptionsSchema.h"

using namespace urbanslam::common;

namespace {

struct Opts {
  double range_m = 10;
  int count = 3;
  bool flag = false;
  std::string mode = "a";
  double needed = 0;
};

OptionsSchema schemaFor(Opts& o, bool with_required) {
  OptionsSchema s;
  s.section("sensor", "sensor options");
  s.add("range_m", o.range_m, 0.0, 100.0, "m", "maximum range");
  s.add("count", o.count, 1, 10, "", "how many");
  s.add("flag", o.flag, "a switch");
  s.add("mode", o.mode, {"a", "b"}, "mode");
  if (with_required) s.add("needed", o.needed, 0.0, 1.0, "", "must be given", true);
  return s;
}

std::string errorOf(const std::string& text, bool with_required = false) {
  Opts o;
  auto s = schemaFor(o, with_required);
  try {
    s.load(IniFile::parse(text, "my.ini"));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(OptionsSchema, LoadsValuesIntoMembers) {
  Opts o;
  auto s = schemaFor(o, false);
  s.load(IniFile::parse("[sensor]\nrange_m = 42.5\ncount = 7\nflag = true\nmode = b\n", "my.ini"));
  EXPECT_DOUBLE_EQ(o.range_m, 42.5);
  EXPECT_EQ(o.count, 7);
  EXPECT_TRUE(o.flag);
  EXPECT_EQ(o.mode, "b");
}

TEST(OptionsSchema, ErrorsNameFileSectionAndKey) {
  const std::string unknown = errorOf("[sensor]\nrange = 3\n");
  EXPECT_NE(unknown.find("my.ini:2"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("[sensor] range"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("unknown key"), std::string::npos) << unknown;

  const std::string range = errorOf("[sensor]\nrange_m = 200\n");
  EXPECT_NE(range.find("[sensor] range_m"), std::string::npos) << range;
  EXPECT_NE(range.find("out of range"), std::string::npos) << range;

  EXPECT_NE(errorOf("[sensor]\ncount = 2.5\n").find("not a whole number"), std::string::npos);
  EXPECT_NE(errorOf("[sensor]\nrange_m = abc\n").find("not a number"), std::string::npos);
  EXPECT_NE(errorOf("[sensor]\nrange_m = nan\n").find("not a number"), std::string::npos);
  EXPECT_NE(errorOf("[sensor]\nflag = maybe\n").find("not a boolean"), std::string::npos);
  EXPECT_NE(errorOf("[sensor]\nmode = c\n").find("not one of a|b"), std::string::npos);
  EXPECT_NE(errorOf("[sensr]\nx = 1\n").find("unknown section [sensr]"), std::string::npos);
  const std::string missing = errorOf("[sensor]\nrange_m = 1\n", true);
  EXPECT_NE(missing.find("[sensor] needed: required key is missing"), std::string::npos) << missing;
  EXPECT_EQ(errorOf("[sensor]\nneeded = 0.5\n", true), "");
}

TEST(OptionsSchema, ResolvedIniReloadsToTheSameValues) {
  Opts a;
  a.range_m = 12.25;
  a.count = 9;
  a.flag = true;
  a.mode = "b";
  auto sa = schemaFor(a, false);
  const std::string text = sa.toIni();
  Opts b;
  auto sb = schemaFor(b, false);
  sb.load(IniFile::parse(text, "resolved.ini"));
  EXPECT_DOUBLE_EQ(b.range_m, 12.25);
  EXPECT_EQ(b.count, 9);
  EXPECT_TRUE(b.flag);
  EXPECT_EQ(b.mode, "b");
  EXPECT_NE(text.find("[m]"), std::string::npos);  // units are documented
}

// An enum option: the ini's name sets the enum value, the resolved ini prints the name back, and
// a name outside the list is an error naming file, line, section and key.
TEST(OptionsSchema, EnumOptionsMapNamesToValues) {
  enum class Kind { First, Second };
  Kind kind = Kind::First;
  OptionsSchema s;
  s.section("s", "");
  s.add<Kind>("kind", kind, {{"first", Kind::First}, {"second", Kind::Second}}, "which");
  s.load(IniFile::parse("[s]\nkind = second\n", "e.ini"));
  EXPECT_EQ(kind, Kind::Second);
  EXPECT_NE(s.toIni().find("kind = second"), std::string::npos) << s.toIni();
  try {
    s.load(IniFile::parse("[s]\nkind = third\n", "e.ini"));
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("e.ini:2: [s] kind: 'third' is not one of first|second"), std::string::npos) << e.what();
  }
  EXPECT_EQ(kind, Kind::Second);
}
