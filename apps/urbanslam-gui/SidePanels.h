#pragma once
// The panels beside the map: run statistics with a time-per-step plot, the loop-closure log,
// the camera frames, and the inspected keyframe.
#include <wx/listctrl.h>
#include <wx/panel.h>
#include <wx/statbmp.h>
#include <wx/stattext.h>

#include <functional>

#include "model/CameraView.h"
#include "model/MapSnapshot.h"

namespace urbanslam::gui {

// Time per step (ms) of the recent scans, drawn as a line plot.
class StepPlot : public wxPanel {
 public:
  explicit StepPlot(wxWindow* parent);
  void setData(const std::vector<double>& step_ms);

 private:
  void onPaint(wxPaintEvent&);
  std::vector<double> data_;
};

class StatsPanel : public wxPanel {
 public:
  explicit StatsPanel(wxWindow* parent);
  void update(const MapSnapshot& s, const std::string& input, const std::string& ini);

 private:
  wxStaticText* text_;
  StepPlot* plot_;
};

class ClosuresPanel : public wxPanel {
 public:
  explicit ClosuresPanel(wxWindow* parent);
  void update(const MapSnapshot& s);
  // Called with the closure's two keyframes when a row is activated.
  std::function<void(size_t from, size_t to)> on_select;

 private:
  wxListCtrl* list_;
  size_t shown_ = 0;
};

// The current (or clicked) keyframe's frame and, beside it, the earlier frame Tree of Words
// matched it with; what to show comes from the model's cameraView().
class CameraPanel : public wxPanel {
 public:
  explicit CameraPanel(wxWindow* parent);
  void update(const CameraView& view);

 private:
  void showFrame(const CameraFrame& f, wxStaticBitmap* bitmap, wxStaticText* caption, const io::CameraImage*& shown);
  wxStaticBitmap *current_, *matched_;
  wxStaticText *current_caption_, *matched_caption_, *match_caption_;
  const io::CameraImage* shown_current_ = nullptr;
  const io::CameraImage* shown_matched_ = nullptr;
  int shown_width_ = 0;
};

class KeyframePanel : public wxPanel {
 public:
  explicit KeyframePanel(wxWindow* parent);
  void show(const MapSnapshot& s, size_t index);

 private:
  wxStaticText* text_;
};

}  // namespace urbanslam::gui
