#include "MapCanvas.h"

#include <GL/gl.h>
#include <mrpt/math/TLine3D.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <wx/image.h>

#include <cmath>

namespace urbanslam::gui {

namespace {

mrpt::img::TColor u8(const Rgb& c) { return {c.r, c.g, c.b}; }

mrpt::opengl::CSetOfLines::Ptr makeLines(const Rgb& c, float width) {
  auto l = mrpt::opengl::CSetOfLines::Create();
  l->setColor_u8(u8(c));
  l->setLineWidth(width);
  return l;
}

}  // namespace

MapCanvas::MapCanvas(wxWindow* parent) : CWxGLCanvasBase(parent, wxID_ANY, wxDefaultPosition, wxSize(800, 600)) {
  auto scene = getOpenGLSceneRef();
  auto vp = scene->getViewport();
  vp->setCustomBackgroundColor({palette::kBackground.r / 255.f, palette::kBackground.g / 255.f, palette::kBackground.b / 255.f});
  auto grid = mrpt::opengl::CGridPlaneXY::Create(-200, 200, -200, 200, 0, 10);
  grid->setColor_u8(mrpt::img::TColor(60, 64, 72));
  scene->insert(grid);
  points_ = mrpt::opengl::CPointCloudColoured::Create();
  points_->setPointSize(2.0f);
  scan_ = mrpt::opengl::CPointCloudColoured::Create();
  scan_->setPointSize(4.0f);
  selected_ = mrpt::opengl::CPointCloudColoured::Create();
  selected_->setPointSize(4.0f);
  trajectory_ = makeLines(palette::kTrajectory, 2);
  accepted_ = makeLines(palette::kClosureAccepted, 2);
  rejected_ = makeLines(palette::kClosureRejected, 1);
  candidates_ = makeLines(palette::kCandidate, 1);
  tracked_ = makeLines(palette::kLocalizedTracked, 3);
  lost_ = makeLines(palette::kLocalizedLost, 3);
  robot_ = makeLines(palette::kCurrentScan, 2);
  ellipse_ = makeLines(palette::kCurrentScan, 1);
  for (const auto& o : std::initializer_list<mrpt::opengl::CRenderizable::Ptr>{points_, trajectory_, rejected_, accepted_, candidates_,
                                                                               tracked_, lost_, scan_, selected_, ellipse_, robot_})
    scene->insert(o);
  setTopView(true);
  Bind(wxEVT_LEFT_DOWN, &MapCanvas::onLeftDown, this);
  Bind(wxEVT_LEFT_UP, &MapCanvas::onLeftUp, this);
}

void MapCanvas::setDrawList(const DrawList& d) {
  points_->clear();
  for (const auto& p : d.map_points) points_->push_back(p.x, p.y, p.z, p.colour.r / 255.f, p.colour.g / 255.f, p.colour.b / 255.f);
  scan_->clear();
  for (const auto& p : d.current_scan) scan_->push_back(p.x, p.y, p.z, p.colour.r / 255.f, p.colour.g / 255.f, p.colour.b / 255.f);
  selected_->clear();
  for (const auto& p : d.selected_scan) selected_->push_back(p.x, p.y, p.z, p.colour.r / 255.f, p.colour.g / 255.f, p.colour.b / 255.f);
  const auto fill = [](mrpt::opengl::CSetOfLines& l, const std::vector<Segment>& segs, float z) {
    l.clear();
    for (const auto& s : segs) l.appendLine(s.x0, s.y0, z, s.x1, s.y1, z);
  };
  fill(*trajectory_, d.trajectory, 0.02f);
  fill(*accepted_, d.closures_accepted, 0.04f);
  fill(*rejected_, d.closures_rejected, 0.03f);
  fill(*tracked_, d.localized_tracked, 0.05f);
  fill(*lost_, d.localized_lost, 0.05f);
  candidates_->clear();
  for (const auto& c : d.candidates) {  // a small cross on each candidate keyframe
    candidates_->appendLine(c.x - 0.4, c.y, 0.05, c.x + 0.4, c.y, 0.05);
    candidates_->appendLine(c.x, c.y - 0.4, 0.05, c.x, c.y + 0.4, 0.05);
  }
  robot_->clear();
  if (d.current_pose) {  // the vehicle as a triangle pointing along its heading
    const auto& p = *d.current_pose;
    const double c = std::cos(p.phi), s = std::sin(p.phi);
    const auto pt = [&](double x, double y) { return std::pair<double, double>{p.x + c * x - s * y, p.y + s * x + c * y}; };
    const auto a = pt(0.6, 0), b = pt(-0.3, 0.3), e = pt(-0.3, -0.3);
    robot_->appendLine(a.first, a.second, 0.06, b.first, b.second, 0.06);
    robot_->appendLine(b.first, b.second, 0.06, e.first, e.second, 0.06);
    robot_->appendLine(e.first, e.second, 0.06, a.first, a.second, 0.06);
  }
  ellipse_->clear();
  if (d.uncertainty) {
    const auto& el = *d.uncertainty;
    const double c = std::cos(el.angle_rad), s = std::sin(el.angle_rad);
    constexpr int kSegments = 48;
    for (int i = 0; i < kSegments; ++i) {
      const double t0 = 2 * M_PI * i / kSegments, t1 = 2 * M_PI * (i + 1) / kSegments;
      const double x0 = el.a * std::cos(t0), y0 = el.b * std::sin(t0), x1 = el.a * std::cos(t1), y1 = el.b * std::sin(t1);
      ellipse_->appendLine(el.cx + c * x0 - s * y0, el.cy + s * x0 + c * y0, 0.06, el.cx + c * x1 - s * y1, el.cy + s * x1 + c * y1, 0.06);
    }
  }
  bounds_ = d.bounds;
  if (!fitted_once_ && !bounds_.empty) {
    fitToMap();
    fitted_once_ = true;
  }
  Refresh(false);
  // Paint now: GTK delivers paint events only when idle, and a busy timer would starve them.
  Update();
}

void MapCanvas::fitToMap() {
  if (bounds_.empty) return;
  const float cx = (bounds_.xmin + bounds_.xmax) / 2, cy = (bounds_.ymin + bounds_.ymax) / 2;
  const float extent = std::max({bounds_.xmax - bounds_.xmin, bounds_.ymax - bounds_.ymin, 10.f});
  centreOn(cx, cy, extent);
}

void MapCanvas::centreOn(double x, double y, double extent_m) {
  setCameraPointing(static_cast<float>(x), static_cast<float>(y), 0);
  // With a 30° field of view the visible height at distance d is ~0.54 d.
  setZoomDistance(static_cast<float>(1.15 * extent_m / 0.54 * (top_view_ ? 1.0 : 0.9)));
  Refresh(false);
}

void MapCanvas::setTopView(bool top) {
  top_view_ = top;
  setElevationDegrees(top ? 90.f : 40.f);
  setAzimuthDegrees(top ? -90.f : -110.f);
  Refresh(false);
}

void MapCanvas::requestScreenshot(const std::string& path, std::function<void(bool)> done) {
  screenshot_path_ = path;
  screenshot_done_ = std::move(done);
  Refresh(false);
  Update();
}

void MapCanvas::OnPostRender() {
  if (screenshot_path_.empty()) return;
  // Read back what was just rendered (the back buffer, before the swap).
  const wxSize sz = GetClientSize();
  const int w = sz.GetWidth(), h = sz.GetHeight();
  std::vector<unsigned char> rgb(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  wxImage img(w, h);
  for (int r = 0; r < h; ++r)  // OpenGL rows start at the bottom
    std::copy_n(rgb.data() + static_cast<size_t>(h - 1 - r) * static_cast<size_t>(w) * 3, static_cast<size_t>(w) * 3,
                img.GetData() + static_cast<size_t>(r) * static_cast<size_t>(w) * 3);
  const std::string path = screenshot_path_;
  const std::string tmp = path + ".partial.png";
  bool ok = img.SaveFile(tmp, wxBITMAP_TYPE_PNG) && std::rename(tmp.c_str(), path.c_str()) == 0;
  screenshot_path_.clear();
  auto done = std::move(screenshot_done_);
  screenshot_done_ = nullptr;
  if (done) CallAfter([done, ok] { done(ok); });
}

void MapCanvas::onLeftDown(wxMouseEvent& e) {
  down_at_ = e.GetPosition();
  e.Skip();  // the base class starts its camera drag
}

void MapCanvas::onLeftUp(wxMouseEvent& e) {
  e.Skip();
  const wxPoint p = e.GetPosition();
  if (std::abs(p.x - down_at_.x) + std::abs(p.y - down_at_.y) > 3 || !on_click) return;
  // Ray through the clicked pixel, intersected with the ground plane z = 0.
  mrpt::math::TLine3D ray;
  const int h = GetClientSize().GetHeight();
  getOpenGLSceneRef()->getViewport()->get3DRayForPixelCoord(p.x, h - 1 - p.y, ray);
  if (std::abs(ray.director[2]) < 1e-9) return;
  const double t = -ray.pBase.z / ray.director[2];
  on_click(ray.pBase.x + t * ray.director[0], ray.pBase.y + t * ray.director[1]);
}

}  // namespace urbanslam::gui
