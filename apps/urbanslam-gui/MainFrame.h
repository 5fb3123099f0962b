#pragma once
// The main window: map view, side panels, menus (File/Run/View/Export), toolbar and status bar.
// The pipeline runs in a PipelineWorker thread (or a LocalizationWorker localizes a log in a
// saved map); a 20 Hz timer redraws from its snapshots.
#include <wx/filehistory.h>
#include <wx/frame.h>
#include <wx/notebook.h>
#include <wx/timer.h>

#include <memory>
#include <string>

#include "MapCanvas.h"
#include "SidePanels.h"
#include "model/DrawList.h"
#include "model/LocalizationWorker.h"
#include "model/PipelineWorker.h"

namespace urbanslam::gui {

// Exit code of the process (set by the frame: 2 for bad input in unattended runs).
inline int g_exit_code = 0;

struct GuiOptions {
  std::string log, ini;
  std::string map;  // localize `log` in this saved map instead of mapping it
  std::string home;  // the project folder (shipped rawlogs, ini, share/)
  bool autorun = false;
  double speed = 0;  // log seconds per wall second; 0: as fast as possible
  bool exit_when_done = false;
  std::string screenshot;
  size_t snapshot_at_keyframes = 0;  // also save `snapshot_path` once this many keyframes are drawn
  std::string snapshot_path;
};

class MainFrame : public wxFrame {
 public:
  explicit MainFrame(const GuiOptions& options);
  ~MainFrame() override;

  // Opens a log with the current ini; errors go to a dialog (the window stays).
  bool openLog(const std::string& path);
  bool loadIni(const std::string& path);
  // Localizes a log in a saved map (map.usmap or its run folder); errors go to a dialog.
  bool localizeLog(const std::string& map_path, const std::string& log_path);

 private:
  void buildMenus();
  void buildToolbar();
  void onTimer(wxTimerEvent&);
  void refreshView(bool force);
  void restart();
  void showError(const std::string& message);
  void exportWith(const wxString& title, const wxString& wildcard, const wxString& default_name,
                  const std::function<void(const slam::Pipeline&, const std::string&)>& write);
  void finishAutomaticRun();
  void reportLocalization(bool screenshot_ok);
  void updateTitle();

  GuiOptions options_;
  std::unique_ptr<PipelineWorker> worker_;           // mapping a log...
  std::unique_ptr<LocalizationWorker> localizer_;  // ...or localizing one in a saved map (one at a time)
  bool finished() const { return worker_ ? worker_->finished() : localizer_ && localizer_->finished(); }
  std::string error() const { return worker_ ? worker_->error() : localizer_ ? localizer_->error() : std::string(); }
  MapCanvas* canvas_ = nullptr;
  wxNotebook* notebook_ = nullptr;
  StatsPanel* stats_ = nullptr;
  ClosuresPanel* closures_ = nullptr;
  CameraPanel* camera_ = nullptr;
  KeyframePanel* keyframe_ = nullptr;
  wxTimer timer_;
  wxFileHistory history_;
  Layers layers_;
  size_t drawn_version_ = static_cast<size_t>(-1);
  MapSnapshot last_snapshot_;
  bool auto_finished_ = false;
  bool snapshot_taken_ = false;
  bool camera_page_shown_ = false;
};

}  // namespace urbanslam::gui
