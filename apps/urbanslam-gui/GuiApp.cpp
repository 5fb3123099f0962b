// urbanslam-gui [FILE] [--ini FILE] [--map MAP] [--autorun] [--speed X] [--screenshot FILE] [--exit-when-done]
#include <wx/app.h>
#include <wx/image.h>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "MainFrame.h"
#include "urbanslam/common/Heap.h"

namespace {

constexpr const char* kUsage =
    "usage: urbanslam-gui [FILE] [--ini FILE] [--map MAP] [--autorun] [--speed X] [--screenshot FILE] [--exit-when-done]\n\n"
    "Opens a log (MRPT rawlog, CARMEN log, Victoria Park folder/zip, folder of images; default: the shipped\n"
    "rawlogs/intel.rawlog) and shows the map and its loop closures as they are built.\n\n"
    "  --ini FILE          configuration (default: ini/default.ini)\n"
    "  --map MAP           localize FILE in a saved map (map.usmap, or the run folder holding it) instead of mapping it\n"
    "  --autorun           start processing at once\n"
    "  --speed X           log seconds per wall second (1: real time); 0 (default): as fast as possible\n"
    "  --screenshot FILE   with --exit-when-done: save the final view as PNG\n"
    "  --exit-when-done    quit when the log is processed; prints one JSON line with what was drawn\n"
    "  --snapshot-at N:FILE  save the view as PNG once N keyframes are drawn (the run goes on)\n";

class GuiApp : public wxApp {
 public:
  bool OnInit() override {
    wxInitAllImageHandlers();
    urbanslam::gui::GuiOptions o;
    const std::string home = [] {
      const char* h = std::getenv("URBANSLAM_HOME");
      return std::string(h && *h ? h : URBANSLAM_SOURCE_DIR);
    }();
    o.ini = home + "/ini/default.ini";
    o.home = home;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i].ToStdString();
      const auto value = [&]() -> std::string {
        if (i + 1 >= argc) {
          std::cerr << "urbanslam-gui: error: " << a << " needs a value\n";
          std::exit(2);
        }
        return argv[++i].ToStdString();
      };
      if (a == "--help" || a == "-h") {
        std::cout << kUsage;
        std::exit(0);
      } else if (a == "--ini")
        o.ini = value();
      else if (a == "--map")
        o.map = value();
      else if (a == "--screenshot")
        o.screenshot = value();
      else if (a == "--autorun")
        o.autorun = true;
      else if (a == "--speed") {
        const std::string v = value();
        char* end = nullptr;
        o.speed = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(o.speed >= 0)) {
          std::cerr << "urbanslam-gui: error: --speed expects a number >= 0, got '" << v << "'\n";
          std::exit(2);
        }
      } else if (a == "--snapshot-at") {
        const std::string v = value();
        const auto colon = v.find(':');
        char* end = nullptr;
        const unsigned long n = colon == std::string::npos ? 0 : std::strtoul(v.c_str(), &end, 10);
        if (colon == std::string::npos || n == 0 || end != v.c_str() + colon) {
          std::cerr << "urbanslam-gui: error: --snapshot-at expects N:FILE, got '" << v << "'\n";
          std::exit(2);
        }
        o.snapshot_at_keyframes = n;
        o.snapshot_path = v.substr(colon + 1);
      } else if (a == "--exit-when-done")
        o.exit_when_done = true;
      else if (a.rfind("--", 0) == 0) {
        std::cerr << "urbanslam-gui: error: unknown option " << a << " (see --help)\n";
        std::exit(2);
      } else
        o.log = a;
    }
    if (o.log.empty()) o.log = home + "/rawlogs/intel.rawlog";
    frame_ = new urbanslam::gui::MainFrame(o);
    frame_->Show();
    return true;
  }
  int OnRun() override {
    wxApp::OnRun();
    return urbanslam::gui::g_exit_code;
  }

 private:
  urbanslam::gui::MainFrame* frame_ = nullptr;
};

}  // namespace

wxIMPLEMENT_APP_NO_MAIN(GuiApp);

int main(int argc, char** argv) {
  urbanslam::common::keepFreedBuffers();
  // --help before wx starts: wx's GTK initialisation fails without a display (exit 255), and the
  // help must not need one.
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--ini" || a == "--map" || a == "--screenshot" || a == "--speed" || a == "--snapshot-at") {
      ++i;  // a value, even one spelled "--help"
    } else if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
  }
  return wxEntry(argc, argv);
}
