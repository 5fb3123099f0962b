#pragma once
// The map view: an MRPT OpenGL scene inside our wx window (mrpt::gui::CWxGLCanvasBase). It
// only turns a DrawList into MRPT objects; what to draw is decided by model/DrawList.
#include <mrpt/gui/CWxGLCanvasBase.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>

#include <functional>
#include <optional>
#include <string>

#include "model/DrawList.h"

namespace urbanslam::gui {

class MapCanvas : public mrpt::gui::CWxGLCanvasBase {
 public:
  explicit MapCanvas(wxWindow* parent);

  void setDrawList(const DrawList& d);
  void fitToMap();
  void setTopView(bool top);  // true: 2D top view (orthographic); false: 3D orbit
  bool topView() const { return top_view_; }
  void centreOn(double x, double y, double extent_m);
  // Saves the next rendered frame as PNG; `done(ok)` runs after the file is written.
  void requestScreenshot(const std::string& path, std::function<void(bool)> done);
  // Left click without dragging, in world coordinates (z = 0 plane).
  std::function<void(double x, double y)> on_click;

 protected:
  void OnPostRender() override;

 private:
  void onLeftDown(wxMouseEvent& e);
  void onLeftUp(wxMouseEvent& e);

  mrpt::opengl::CPointCloudColoured::Ptr points_, scan_, selected_;
  mrpt::opengl::CSetOfLines::Ptr trajectory_, accepted_, rejected_, candidates_, tracked_, lost_, robot_, ellipse_;
  Bounds bounds_;
  bool top_view_ = true;
  bool fitted_once_ = false;
  wxPoint down_at_;
  std::string screenshot_path_;
  std::function<void(bool)> screenshot_done_;
};

}  // namespace urbanslam::gui
