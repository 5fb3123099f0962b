#include "MainFrame.h"

#include <wx/artprov.h>
#include <wx/config.h>
#include <wx/dnd.h>
#include <wx/filedlg.h>
#include <wx/dirdlg.h>
#include <wx/menu.h>
#include <wx/msgdlg.h>
#include <wx/sizer.h>
#include <wx/splitter.h>
#include <wx/statusbr.h>
#include <wx/toolbar.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "urbanslam/common/Error.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/slam/MovingPoints.h"
#include "urbanslam/slam/RunOutputs.h"

namespace urbanslam::gui {

namespace {

enum Ids {
  kOpen = wxID_HIGHEST + 1,
  kLocalize,
  kLoadIni,
  kPlay,
  kPause,
  kStep,
  kRestart,
  kSpeedMax,
  kSpeedReal,
  kSpeed10,
  kFit,
  kTop,
  kOrbit,
  kLayerPoints,
  kLayerTrajectory,
  kLayerScan,
  kLayerUncertainty,
  kLayerAccepted,
  kLayerRejected,
  kLayerCandidates,
  kColourAge,
  kColourHeight,
  kExportPly,
  kExportPcd,
  kExportXyz,
  kExportTum,
  kExportGrid,
  kExportSimplemap,
  kExportAll,
  kExportScreenshot,
  kExportGraph
};

// Dropping a file on the window opens it (the first one).
class DropTarget : public wxFileDropTarget {
 public:
  explicit DropTarget(MainFrame* frame) : frame_(frame) {}
  bool OnDropFiles(wxCoord, wxCoord, const wxArrayString& files) override {
    return !files.empty() && frame_->openLog(files[0].ToStdString());
  }

 private:
  MainFrame* frame_;
};

}  // namespace

MainFrame::MainFrame(const GuiOptions& options)
    : wxFrame(nullptr, wxID_ANY, "urbanslam", wxDefaultPosition, wxSize(1280, 800)), options_(options), timer_(this) {
  buildMenus();
  buildToolbar();
  CreateStatusBar(2);
  auto* split = new wxSplitterWindow(this, wxID_ANY, wxDefaultPosition, wxDefaultSize, wxSP_LIVE_UPDATE);
  canvas_ = new MapCanvas(split);
  notebook_ = new wxNotebook(split, wxID_ANY);
  stats_ = new StatsPanel(notebook_);
  closures_ = new ClosuresPanel(notebook_);
  camera_ = new CameraPanel(notebook_);
  keyframe_ = new KeyframePanel(notebook_);
  notebook_->AddPage(stats_, "Statistics");
  notebook_->AddPage(closures_, "Loop closures");
  notebook_->AddPage(camera_, "Camera");
  notebook_->AddPage(keyframe_, "Keyframe");
  split->SplitVertically(canvas_, notebook_, -440);  // room for two camera frames side by side
  split->SetSashGravity(1.0);
  split->SetMinimumPaneSize(200);
  SetDropTarget(new DropTarget(this));

  closures_->on_select = [this](size_t from, size_t to) {
    if (from >= last_snapshot_.keyframes.size() || to >= last_snapshot_.keyframes.size()) return;
    const auto& a = last_snapshot_.keyframes[from].pose;
    const auto& b = last_snapshot_.keyframes[to].pose;
    canvas_->centreOn((a.x + b.x) / 2, (a.y + b.y) / 2, std::max(10.0, 2 * std::hypot(a.x - b.x, a.y - b.y)));
  };
  canvas_->on_click = [this](double x, double y) {
    const double tolerance = std::max(0.5, canvas_->getZoomDistance() * 0.02);
    if (const auto k = pickKeyframe(last_snapshot_, x, y, tolerance)) {
      keyframe_->show(last_snapshot_, *k);
      layers_.selected_keyframe = *k;
      // A keyframe with an image is shown on the camera page (with its Tree of Words match).
      const bool has_image = *k < last_snapshot_.keyframes.size() && last_snapshot_.keyframes[*k].image;
      notebook_->SetSelection(has_image ? 2 : 3);
      refreshView(true);
    }
  };

  wxConfig config("urbanslam-gui");
  history_.Load(config);
  Bind(wxEVT_TIMER, &MainFrame::onTimer, this);
  timer_.Start(50);  // redraw at most 20 Hz
  if (!options_.map.empty())
    localizeLog(options_.map, options_.log);
  else if (!options_.log.empty())
    openLog(options_.log);
  updateTitle();
}

MainFrame::~MainFrame() {
  timer_.Stop();
  wxConfig config("urbanslam-gui");
  history_.Save(config);
  worker_.reset();  // joins the pipeline thread
  localizer_.reset();
}

void MainFrame::buildMenus() {
  auto* file = new wxMenu;
  file->Append(kOpen, "&Open log...\tCtrl+O", "Open an MRPT rawlog, CARMEN log or Victoria Park folder/zip");
  auto* recent = new wxMenu;
  file->AppendSubMenu(recent, "Open &recent");
  history_.UseMenu(recent);
  history_.AddFilesToMenu(recent);
  file->Append(kLoadIni, "Load &ini...\tCtrl+I", "Switch the configuration (restarts the run)");
  file->Append(kLocalize, "&Localize a log in a map...\tCtrl+L", "Track a log's vehicle in a saved map (map.usmap) instead of mapping it");
  file->AppendSeparator();
  auto* exp = new wxMenu;
  exp->Append(kExportAll, "Everything (run folder)...", "All outputs of `urbanslam run` into a folder");
  exp->Append(kExportPly, "Point cloud (PLY)...");
  exp->Append(kExportPcd, "Point cloud (PCD)...");
  exp->Append(kExportXyz, "Point cloud (XYZ)...");
  exp->Append(kExportTum, "Trajectory (TUM)...");
  exp->Append(kExportGrid, "Occupancy grid (PNG + YAML)...");
  exp->Append(kExportSimplemap, "MRPT simplemap...");
  exp->Append(kExportGraph, "Pose graph (g2o)...");
  exp->Append(kExportScreenshot, "Screenshot of the view (PNG)...\tCtrl+P");
  file->AppendSubMenu(exp, "&Export");
  file->AppendSeparator();
  file->Append(wxID_EXIT, "&Quit\tCtrl+Q");

  auto* run = new wxMenu;
  run->Append(kPlay, "&Play\tSpace");
  run->Append(kPause, "P&ause\tCtrl+Space");
  run->Append(kStep, "&Step one keyframe\tN");
  run->Append(kRestart, "&Restart\tCtrl+R");
  run->AppendSeparator();
  run->AppendRadioItem(kSpeedMax, "As fast as possible");
  run->AppendRadioItem(kSpeedReal, "Real time");
  run->AppendRadioItem(kSpeed10, "10x real time");

  auto* view = new wxMenu;
  view->Append(kFit, "&Fit to map\tF");
  view->AppendRadioItem(kTop, "2D top view\t2");
  view->AppendRadioItem(kOrbit, "3D orbit\t3");
  view->AppendSeparator();
  view->AppendCheckItem(kLayerPoints, "Map points")->Check();
  view->AppendCheckItem(kLayerTrajectory, "Trajectory")->Check();
  view->AppendCheckItem(kLayerScan, "Current scan")->Check();
  view->AppendCheckItem(kLayerUncertainty, "Uncertainty ellipse")->Check();
  view->AppendCheckItem(kLayerAccepted, "Accepted loop closures")->Check();
  view->AppendCheckItem(kLayerRejected, "Rejected loop closures")->Check();
  view->AppendCheckItem(kLayerCandidates, "Candidate set")->Check();
  view->AppendSeparator();
  view->AppendRadioItem(kColourAge, "Colour points by keyframe age");
  view->AppendRadioItem(kColourHeight, "Colour points by height");

  auto* bar = new wxMenuBar;
  bar->Append(file, "&File");
  bar->Append(run, "&Run");
  bar->Append(view, "&View");
  SetMenuBar(bar);

  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        wxFileDialog dlg(this, "Open log", "", "", "Logs (*.rawlog;*.log;*.gz;*.clf;*.zip)|*.rawlog;*.log;*.gz;*.clf;*.zip|All files|*",
                         wxFD_OPEN | wxFD_FILE_MUST_EXIST);
        if (dlg.ShowModal() == wxID_OK) openLog(dlg.GetPath().ToStdString());
      },
      kOpen);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent& e) {
        const wxString f = history_.GetHistoryFile(static_cast<size_t>(e.GetId() - wxID_FILE1));
        if (!f.empty()) openLog(f.ToStdString());
      },
      wxID_FILE1, wxID_FILE9);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        wxFileDialog dlg(this, "Load ini", "", "", "ini files (*.ini)|*.ini|All files|*", wxFD_OPEN | wxFD_FILE_MUST_EXIST);
        if (dlg.ShowModal() == wxID_OK) loadIni(dlg.GetPath().ToStdString());
      },
      kLoadIni);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        wxFileDialog map(this, "Open map", "", "map.usmap", "urbanslam maps (*.usmap)|*.usmap|All files|*",
                         wxFD_OPEN | wxFD_FILE_MUST_EXIST);
        if (map.ShowModal() != wxID_OK) return;
        wxFileDialog log(this, "Log to localize", "", "",
                         "Logs (*.rawlog;*.log;*.gz;*.clf;*.zip)|*.rawlog;*.log;*.gz;*.clf;*.zip|All files|*",
                         wxFD_OPEN | wxFD_FILE_MUST_EXIST);
        if (log.ShowModal() == wxID_OK) localizeLog(map.GetPath().ToStdString(), log.GetPath().ToStdString());
      },
      kLocalize);
  Bind(
      wxEVT_MENU, [this](wxCommandEvent&) { Close(); }, wxID_EXIT);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (worker_) worker_->play();
        if (localizer_) localizer_->play();
      },
      kPlay);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (worker_) worker_->pause();
        if (localizer_) localizer_->pause();
      },
      kPause);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (worker_) worker_->stepKeyframe();
        if (localizer_) localizer_->stepScan();
      },
      kStep);
  Bind(
      wxEVT_MENU, [this](wxCommandEvent&) { restart(); }, kRestart);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (worker_) worker_->setSpeed(0);
        if (localizer_) localizer_->setSpeed(0);
      },
      kSpeedMax);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (worker_) worker_->setSpeed(1);
        if (localizer_) localizer_->setSpeed(1);
      },
      kSpeedReal);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (worker_) worker_->setSpeed(10);
        if (localizer_) localizer_->setSpeed(10);
      },
      kSpeed10);
  Bind(
      wxEVT_MENU, [this](wxCommandEvent&) { canvas_->fitToMap(); }, kFit);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        canvas_->setTopView(true);
        canvas_->fitToMap();
      },
      kTop);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        canvas_->setTopView(false);
        canvas_->fitToMap();
      },
      kOrbit);
  const auto layer = [this](int id, bool Layers::*member) {
    Bind(
        wxEVT_MENU,
        [this, member](wxCommandEvent& e) {
          layers_.*member = e.IsChecked();
          refreshView(true);
        },
        id);
  };
  layer(kLayerPoints, &Layers::map_points);
  layer(kLayerTrajectory, &Layers::trajectory);
  layer(kLayerScan, &Layers::current_scan);
  layer(kLayerUncertainty, &Layers::uncertainty);
  layer(kLayerAccepted, &Layers::closures_accepted);
  layer(kLayerRejected, &Layers::closures_rejected);
  layer(kLayerCandidates, &Layers::candidates);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        layers_.colouring = PointColouring::KeyframeAge;
        refreshView(true);
      },
      kColourAge);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        layers_.colouring = PointColouring::Height;
        refreshView(true);
      },
      kColourHeight);

  // Exports use the same writers and the same moving-point removal as `urbanslam run`.
  const auto cloud = [](const slam::Pipeline& p) {
    const auto posed = p.posedKeyframes();
    const slam::MapOptions& m = p.options().map;
    if (!m.remove_moving_points) return io::mapPoints(posed, m.point_decimation);
    const io::PointMask keep = slam::findMovingPoints(posed, m.movingPoints()).static_points;
    return io::mapPoints(posed, m.point_decimation, &keep);
  };
  Bind(
      wxEVT_MENU,
      [this, cloud](wxCommandEvent&) {
        exportWith("Export point cloud", "PLY (*.ply)|*.ply", "map.ply", [cloud](const slam::Pipeline& p, const std::string& f) {
          io::writePly(f, cloud(p), io::PlyEncoding::BinaryLittleEndian);
        });
      },
      kExportPly);
  Bind(
      wxEVT_MENU,
      [this, cloud](wxCommandEvent&) {
        exportWith("Export point cloud", "PCD (*.pcd)|*.pcd", "map.pcd",
                   [cloud](const slam::Pipeline& p, const std::string& f) { io::writePcd(f, cloud(p)); });
      },
      kExportPcd);
  Bind(
      wxEVT_MENU,
      [this, cloud](wxCommandEvent&) {
        exportWith("Export point cloud", "XYZ (*.xyz)|*.xyz", "map.xyz",
                   [cloud](const slam::Pipeline& p, const std::string& f) { io::writeXyz(f, cloud(p)); });
      },
      kExportXyz);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        exportWith("Export trajectory", "TUM (*.tum;*.txt)|*.tum;*.txt", "trajectory.tum",
                   [](const slam::Pipeline& p, const std::string& f) {
                     std::vector<io::StampedPose> t;
                     for (const auto& k : p.keyframes()) t.push_back({k.timestamp, k.pose});
                     io::writeTum(f, t);
                   });
      },
      kExportTum);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        exportWith("Export occupancy grid", "PNG (*.png)|*.png", "grid.png", [](const slam::Pipeline& p, const std::string& f) {
          io::OccupancyGridOptions g;
          g.resolution_m = p.options().map.grid_resolution_m;
          std::string prefix = f;
          if (prefix.size() > 4 && prefix.substr(prefix.size() - 4) == ".png") prefix.resize(prefix.size() - 4);
          io::writeOccupancyGrid(prefix, p.posedKeyframes(), g);
        });
      },
      kExportGrid);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        exportWith("Export simplemap", "MRPT simplemap (*.simplemap)|*.simplemap", "map.simplemap",
                   [](const slam::Pipeline& p, const std::string& f) { io::writeSimpleMap(f, p.posedKeyframes()); });
      },
      kExportSimplemap);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        exportWith("Export pose graph", "g2o (*.g2o)|*.g2o", "pose_graph.g2o",
                   [](const slam::Pipeline& p, const std::string& f) { slam::writePoseGraphG2o(p, f); });
      },
      kExportGraph);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        if (!worker_) return;
        wxDirDialog dlg(this, "Export every output into a folder");
        if (dlg.ShowModal() != wxID_OK) return;
        const std::string dir = dlg.GetPath().ToStdString();
        try {
          worker_->withPipeline([&](const slam::Pipeline& p) {
            slam::writeRunOutputs(p, dir,
                                  {worker_->logPath(), worker_->inputFormat(), worker_->iniPath(), worker_->resolvedIni(), {}, {}, {}, {}});
          });
          SetStatusText("exported to " + dir, 0);
        } catch (const std::exception& e) {
          showError(e.what());
        }
      },
      kExportAll);
  Bind(
      wxEVT_MENU,
      [this](wxCommandEvent&) {
        wxFileDialog dlg(this, "Save screenshot", "", "view.png", "PNG (*.png)|*.png", wxFD_SAVE | wxFD_OVERWRITE_PROMPT);
        if (dlg.ShowModal() != wxID_OK) return;
        const std::string path = dlg.GetPath().ToStdString();
        canvas_->requestScreenshot(path, [this, path](bool ok) {
          if (ok)
            SetStatusText("saved " + path, 0);
          else
            showError(path + ": cannot write");
        });
      },
      kExportScreenshot);
}

void MainFrame::buildToolbar() {
  auto* tb = CreateToolBar(wxTB_HORIZONTAL | wxTB_TEXT);
  tb->AddTool(kOpen, "Open", wxArtProvider::GetBitmap(wxART_FILE_OPEN, wxART_TOOLBAR));
  tb->AddSeparator();
  tb->AddTool(kPlay, "Play", wxArtProvider::GetBitmap(wxART_GO_FORWARD, wxART_TOOLBAR));
  tb->AddTool(kPause, "Pause", wxArtProvider::GetBitmap(wxART_CROSS_MARK, wxART_TOOLBAR));
  tb->AddTool(kStep, "Step", wxArtProvider::GetBitmap(wxART_GOTO_LAST, wxART_TOOLBAR));
  tb->AddTool(kRestart, "Restart", wxArtProvider::GetBitmap(wxART_REDO, wxART_TOOLBAR));
  tb->AddSeparator();
  tb->AddTool(kFit, "Fit", wxArtProvider::GetBitmap(wxART_FULL_SCREEN, wxART_TOOLBAR));
  tb->Realize();
}

void MainFrame::showError(const std::string& message) {
  std::cerr << "urbanslam-gui: error: " << message << "\n";
  if (options_.exit_when_done) {  // unattended: report and leave, never block on a dialog
    g_exit_code = common::kExitBadInput;
    CallAfter([this] { Close(true); });
    return;
  }
  wxMessageBox("error: " + message, "urbanslam", wxOK | wxICON_ERROR, this);
}

bool MainFrame::openLog(const std::string& path) {
  try {
    auto worker = std::make_unique<PipelineWorker>(path, options_.ini, options_.home);
    worker_.reset();  // the previous run's thread ends first
    localizer_.reset();
    worker_ = std::move(worker);
  } catch (const std::exception& e) {
    showError(e.what());
    return false;
  }
  options_.log = path;
  options_.map.clear();
  history_.AddFileToHistory(path);
  drawn_version_ = static_cast<size_t>(-1);
  auto_finished_ = false;
  snapshot_taken_ = false;
  camera_page_shown_ = false;
  worker_->setSpeed(options_.speed);
  if (options_.autorun) worker_->play();
  updateTitle();
  return true;
}

bool MainFrame::localizeLog(const std::string& map_path, const std::string& log_path) {
  try {
    auto localizer = std::make_unique<LocalizationWorker>(map_path, log_path);
    worker_.reset();
    localizer_.reset();  // the previous run's thread ends first
    localizer_ = std::move(localizer);
  } catch (const std::exception& e) {
    showError(e.what());
    return false;
  }
  options_.log = log_path;
  options_.map = map_path;
  history_.AddFileToHistory(log_path);
  drawn_version_ = static_cast<size_t>(-1);
  auto_finished_ = false;
  snapshot_taken_ = false;
  layers_.selected_keyframe.reset();
  localizer_->setSpeed(options_.speed);
  if (options_.autorun) localizer_->play();
  updateTitle();
  return true;
}

bool MainFrame::loadIni(const std::string& path) {
  const std::string previous = options_.ini;
  options_.ini = path;
  if (options_.log.empty() || openLog(options_.log)) {
    updateTitle();
    return true;
  }
  options_.ini = previous;
  return false;
}

void MainFrame::restart() {
  if (!options_.map.empty())
    localizeLog(options_.map, options_.log);
  else if (!options_.log.empty())
    openLog(options_.log);
}

void MainFrame::updateTitle() {
  SetTitle("urbanslam — " + (options_.log.empty() ? std::string("no log") : options_.log) +
           (options_.map.empty() ? std::string() : " localized in " + options_.map));
  SetStatusText("ini: " + options_.ini, 1);
}

void MainFrame::exportWith(const wxString& title, const wxString& wildcard, const wxString& default_name,
                           const std::function<void(const slam::Pipeline&, const std::string&)>& write) {
  if (!worker_) {
    SetStatusText("exports are of a mapping run (urbanslam localize --out writes a localization's outputs)", 0);
    return;
  }
  wxFileDialog dlg(this, title, "", default_name, wildcard, wxFD_SAVE | wxFD_OVERWRITE_PROMPT);
  if (dlg.ShowModal() != wxID_OK) return;
  const std::string path = dlg.GetPath().ToStdString();
  try {
    worker_->withPipeline([&](const slam::Pipeline& p) { write(p, path); });
    SetStatusText("exported " + path, 0);
  } catch (const std::exception& e) {
    showError(e.what());
  }
}

void MainFrame::refreshView(bool force) {
  if (!worker_ && !localizer_) return;
  const size_t v = worker_ ? worker_->collector().version() : localizer_->version();
  if (!force && v == drawn_version_) return;
  drawn_version_ = v;
  last_snapshot_ = worker_ ? worker_->collector().snapshot() : localizer_->snapshot();
  canvas_->setDrawList(buildDrawList(last_snapshot_, layers_));
  stats_->update(last_snapshot_, options_.log, worker_ ? worker_->iniPath() : "map " + localizer_->mapPath());
  closures_->update(last_snapshot_);
  camera_->update(cameraView(last_snapshot_, layers_.selected_keyframe));
  if (!camera_page_shown_ && !last_snapshot_.keyframes.empty() && last_snapshot_.keyframes.back().image) {
    camera_page_shown_ = true;  // a log with images: show them (once; the user may switch away)
    notebook_->SetSelection(2);
  }
  if (last_snapshot_.localizing)
    SetStatusText(
        wxString::Format("localizing in %zu keyframes: %zu scans, %zu lost, %zu relocalisations, %.0f %%%s",
                         last_snapshot_.keyframes.size(), last_snapshot_.stats.scans, last_snapshot_.lost_scans,
                         last_snapshot_.relocalisations, 100 * last_snapshot_.stats.progress, last_snapshot_.finished ? " - finished" : ""),
        0);
  else
    SetStatusText(wxString::Format("%zu keyframes, %.0f %%%s", last_snapshot_.stats.keyframes, 100 * last_snapshot_.stats.progress,
                                   last_snapshot_.finished ? " - finished" : ""),
                  0);
}

void MainFrame::onTimer(wxTimerEvent&) {
  refreshView(false);
  if (!worker_ && !localizer_) return;
  // --snapshot-at N:FILE: a picture of the view mid-run (the run goes on).
  if (!snapshot_taken_ && options_.snapshot_at_keyframes > 0 && last_snapshot_.keyframes.size() >= options_.snapshot_at_keyframes) {
    snapshot_taken_ = true;
    canvas_->fitToMap();
    canvas_->requestScreenshot(options_.snapshot_path, [this](bool ok) {
      if (!ok) std::cerr << "urbanslam-gui: error: " << options_.snapshot_path << ": cannot write\n";
    });
  }
  const std::string err = error();
  if (!err.empty() && !auto_finished_) {
    auto_finished_ = true;
    showError(err);
    return;
  }
  if (options_.exit_when_done && finished() && last_snapshot_.finished && !auto_finished_) {
    auto_finished_ = true;
    finishAutomaticRun();
  }
}

// --exit-when-done with --map: what the localization drew, as one JSON line; then exit.
void MainFrame::reportLocalization(bool screenshot_ok) {
  const DrawList d = buildDrawList(last_snapshot_, layers_);
  std::printf(
      "{\"keyframes_drawn\":%zu,\"map_points_drawn\":%zu,\"localized_scans\":%zu,\"localized_poses\":%zu,\"lost_scans\":%zu,"
      "\"relocalisations\":%zu,\"tracked_segments\":%zu,\"lost_segments\":%zu,\"screenshot\":\"%s\",\"screenshot_ok\":%s}\n",
      d.keyframes_drawn, d.map_points.size(), last_snapshot_.stats.scans, last_snapshot_.localized.size(), last_snapshot_.lost_scans,
      last_snapshot_.relocalisations, d.localized_tracked.size(), d.localized_lost.size(), options_.screenshot.c_str(),
      screenshot_ok ? "true" : "false");
  std::fflush(stdout);
  if (!screenshot_ok) g_exit_code = 1;
  Close(true);
}

// --exit-when-done: fit the view, take the screenshot if asked, report what was drawn, exit.
void MainFrame::finishAutomaticRun() {
  canvas_->fitToMap();
  const auto report = [this](bool screenshot_ok) {
    if (localizer_) {
      reportLocalization(screenshot_ok);
      return;
    }
    size_t pipeline_keyframes = 0;
    worker_->withPipeline([&](const slam::Pipeline& p) { pipeline_keyframes = p.keyframes().size(); });
    const DrawList d = buildDrawList(last_snapshot_, layers_);
    // What the camera panel shows (from the model), so tests need not read pixels.
    const CameraView cam = cameraView(last_snapshot_, layers_.selected_keyframe);
    const auto id = [](const CameraFrame& f) { return f.image && f.keyframe ? static_cast<long>(*f.keyframe) : -1L; };
    std::printf(
        "{\"keyframes_drawn\":%zu,\"keyframes\":%zu,\"map_points_drawn\":%zu,\"image_keyframes\":%zu,"
        "\"image_matches\":%zu,\"camera_current_keyframe\":%ld,\"camera_matched_keyframe\":%ld,"
        "\"camera_match_score\":%.4f,\"camera_match_fate\":\"%s\",\"screenshot\":\"%s\",\"screenshot_ok\":%s}\n",
        d.keyframes_drawn, pipeline_keyframes, d.map_points.size(),
        static_cast<size_t>(std::count_if(last_snapshot_.keyframes.begin(), last_snapshot_.keyframes.end(),
                                          [](const KeyframeView& k) { return k.image != nullptr; })),
        last_snapshot_.image_matches.size(), id(cam.current), id(cam.matched), cam.match ? cam.match->score : 0.0,
        cam.match ? cam.match->fate.c_str() : "", options_.screenshot.c_str(), screenshot_ok ? "true" : "false");
    std::fflush(stdout);
    if (!screenshot_ok) g_exit_code = 1;
    Close(true);
  };
  if (options_.screenshot.empty()) {
    report(true);
    return;
  }
  // Give the canvas a few frames to settle (first GL frame, fit) before reading it back.
  CallAfter([this, report] {
    canvas_->Refresh(false);
    canvas_->Update();
    canvas_->requestScreenshot(options_.screenshot, report);
  });
}

}  // namespace urbanslam::gui
