// The real window under Xvfb on the shipped rawlog: exits 0, draws as many keyframes as the CLI
// reports for the same input, and the screenshot shows the map.
#include <gtest/gtest.h>

#include <mrpt/img/CImage.h>

#include <cstdlib>
#include <filesystem>

#include "CliRunner.h"
#include "model/DrawList.h"

using namespace urbanslam;
namespace fs = std::filesystem;

namespace {
size_t jsonCount(const std::string& json, const std::string& key) {
  const auto p = json.find("\"" + key + "\":");
  if (p == std::string::npos) return static_cast<size_t>(-1);
  return std::stoul(json.substr(p + key.size() + 3));
}
}  // namespace

TEST(GuiSmoke, AutorunUnderXvfbDrawsTheMap) {
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) GTEST_SKIP() << "xvfb-run not installed (make deps)";
  const fs::path d = test::scratchDir("gui_smoke");
  const std::string shot = (d / "view.png").string(), out = (d / "gui.json").string();
  const std::string cmd = "xvfb-run -a -s '-screen 0 1280x800x24' " + std::string(URBANSLAM_GUI) +
                          " --autorun --exit-when-done --screenshot " + shot + " > " + out + " 2>" + (d / "err.txt").string();
  const int status = std::system(cmd.c_str());
  const std::string json = test::slurp(out);
  ASSERT_EQ(WEXITSTATUS(status), 0) << json << test::slurp((d / "err.txt").string());
  const test::CliResult cli = test::runCli("run --quiet --json --out " + (d / "cli").string());
  ASSERT_EQ(cli.code, 0);
  const size_t cli_keyframes = jsonCount(cli.out, "keyframes");
  EXPECT_EQ(jsonCount(json, "keyframes_drawn"), cli_keyframes) << json;
  EXPECT_GT(cli_keyframes, 100u);

  mrpt::img::CImage img;
  ASSERT_TRUE(img.loadFromFile(shot)) << shot;
  const auto bg = gui::palette::kBackground;
  size_t map = 0, total = 0;
  for (unsigned y = 0; y < img.getHeight(); y += 2)
    for (unsigned x = 0; x < img.getWidth(); x += 2) {
      const uint8_t* px = img.ptr<uint8_t>(x, y);  // BGR
      const int b = px[0], g = px[1], r = px[2];
      ++total;
      // Map points are coloured (saturated); the background and grid are grey.
      const int spread = std::max({r, g, b}) - std::min({r, g, b});
      if (spread > 60 && std::abs(r - bg.r) + std::abs(g - bg.g) + std::abs(b - bg.b) > 90) ++map;
    }
  EXPECT_GT(static_cast<double>(map) / static_cast<double>(total), 0.02) << map << " of " << total << " pixels in map colours";
}

// The camera-only RTAB-Map excerpt with Tree of Words: the camera panel's model holds the
// current keyframe's frame and the matched earlier frame at the end, and the GUI saw as many
// proposals as the CLI reports for the same input and ini.
TEST(GuiSmoke, CameraPanelShowsBothFramesOnTheImageSequence) {
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) GTEST_SKIP() << "xvfb-run not installed (make deps)";
  const fs::path d = test::scratchDir("gui_smoke_images");
  const std::string input = test::repoPath("rawlogs/rtabmap-loop-excerpt"), ini = test::repoPath("ini/rtabmap-excerpt.ini");
  const std::string shot = (d / "view.png").string(), out = (d / "gui.json").string();
  const std::string cmd = "xvfb-run -a -s '-screen 0 1280x800x24' " + std::string(URBANSLAM_GUI) + " " + input + " --ini " + ini +
                          " --autorun --exit-when-done --screenshot " + shot + " > " + out + " 2>" + (d / "err.txt").string();
  const int status = std::system(cmd.c_str());
  const std::string json = test::slurp(out);
  ASSERT_EQ(WEXITSTATUS(status), 0) << json << test::slurp((d / "err.txt").string());
  const test::CliResult cli = test::runCli("run --quiet --json --ini " + ini + " --out " + (d / "cli").string() + " " + input);
  ASSERT_EQ(cli.code, 0) << cli.err;
  EXPECT_EQ(jsonCount(json, "keyframes_drawn"), jsonCount(cli.out, "keyframes")) << json;
  EXPECT_EQ(jsonCount(json, "image_keyframes"), 32u) << json;
  EXPECT_EQ(jsonCount(json, "image_matches"), jsonCount(cli.out, "image_proposals")) << json << cli.out;
  EXPECT_GT(jsonCount(json, "image_matches"), 0u) << json;
  // Both frames on the panel: the proposing keyframe and an earlier matched one.
  const long current = std::stol(json.substr(json.find("\"camera_current_keyframe\":") + 26));
  const long matched = std::stol(json.substr(json.find("\"camera_matched_keyframe\":") + 26));
  EXPECT_GE(matched, 0) << json;
  EXPECT_GT(current, matched) << json;
  EXPECT_NE(json.find("\"camera_match_fate\":\"no_scans\""), std::string::npos) << json;
  EXPECT_TRUE(fs::exists(shot));
}

// The help needs no display: it is printed before wx initialises GTK (which fails without one).
TEST(GuiSmoke, HelpWithoutADisplay) {
  const fs::path d = test::scratchDir("gui_help");
  const std::string out = (d / "out.txt").string(), err = (d / "err.txt").string();
  for (const char* flag : {"--help", "-h"}) {
    const std::string cmd = "env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(URBANSLAM_GUI) + " " + flag + " >" + out + " 2>" + err;
    const int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << flag << ": " << test::slurp(err);
    EXPECT_EQ(test::slurp(out).rfind("usage: urbanslam-gui", 0), 0u) << test::slurp(out);
  }
}

// Localization mode: the Intel excerpt mapped by the CLI, then localized in that map by the
// window. It draws the map's keyframes and localizes every scan the CLI's `localize` does, with
// the same number lost, and the screenshot shows the vehicle's path in the tracked colour.
TEST(GuiSmoke, LocalizesALogInASavedMap) {
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) GTEST_SKIP() << "xvfb-run not installed (make deps)";
  const fs::path d = test::scratchDir("gui_smoke_localize");
  const std::string log = test::repoPath("rawlogs/intel-corrected-excerpt.log.gz");
  const test::CliResult run = test::runCli("run --quiet --json --out " + (d / "map").string() + " " + log);
  ASSERT_EQ(run.code, 0) << run.err;
  const test::CliResult loc = test::runCli("localize --quiet --json --map " + (d / "map").string() + " --out " + (d / "loc").string() + " " + log);
  ASSERT_EQ(loc.code, 0) << loc.err;
  const std::string shot = (d / "view.png").string(), out = (d / "gui.json").string();
  const std::string cmd = "xvfb-run -a -s '-screen 0 1280x800x24' " + std::string(URBANSLAM_GUI) + " --map " + (d / "map").string() + " " +
                          log + " --autorun --exit-when-done --screenshot " + shot + " > " + out + " 2>" + (d / "err.txt").string();
  const int status = std::system(cmd.c_str());
  const std::string json = test::slurp(out);
  ASSERT_EQ(WEXITSTATUS(status), 0) << json << test::slurp((d / "err.txt").string());
  EXPECT_EQ(jsonCount(json, "keyframes_drawn"), jsonCount(run.out, "keyframes")) << json;
  EXPECT_EQ(jsonCount(json, "localized_scans"), jsonCount(loc.out, "scans_used")) << json << loc.out;
  EXPECT_EQ(jsonCount(json, "lost_scans"), jsonCount(loc.out, "lost")) << json << loc.out;
  EXPECT_GT(jsonCount(json, "tracked_segments"), 50u) << json;

  mrpt::img::CImage img;
  ASSERT_TRUE(img.loadFromFile(shot)) << shot;
  // The tracked colour is a green no map point has (the age ramp keeps red and blue higher).
  size_t path = 0;
  for (unsigned y = 0; y < img.getHeight(); ++y)
    for (unsigned x = 0; x < img.getWidth(); ++x) {
      const uint8_t* px = img.ptr<uint8_t>(x, y);  // BGR
      if (px[1] > 160 && px[2] < 90 && px[0] < 90) ++path;
    }
  EXPECT_GT(path, 300u) << "pixels in the tracked path's colour";
}
