#include "SidePanels.h"

#include <wx/dcbuffer.h>
#include <wx/sizer.h>

#include <algorithm>
#include <cstdio>

#include "urbanslam/common/Timing.h"

namespace urbanslam::gui {

StepPlot::StepPlot(wxWindow* parent) : wxPanel(parent, wxID_ANY, wxDefaultPosition, wxSize(-1, 140)) {
  SetBackgroundStyle(wxBG_STYLE_PAINT);
  Bind(wxEVT_PAINT, &StepPlot::onPaint, this);
}

void StepPlot::setData(const std::vector<double>& step_ms) {
  data_ = step_ms;
  Refresh(false);
}

void StepPlot::onPaint(wxPaintEvent&) {
  wxAutoBufferedPaintDC dc(this);
  const wxSize sz = GetClientSize();
  dc.SetBackground(wxBrush(wxColour(24, 26, 30)));
  dc.Clear();
  dc.SetTextForeground(wxColour(200, 200, 200));
  if (data_.size() < 2) {
    dc.DrawText("time per step (ms)", 6, 4);
    return;
  }
  const double top = std::max(1e-3, urbanslam::common::percentile(data_, 99.5) * 1.1);
  dc.SetPen(wxPen(wxColour(255, 210, 60)));
  const double w = sz.GetWidth() - 8, h = sz.GetHeight() - 22;
  for (size_t i = 1; i < data_.size(); ++i) {
    const auto px = [&](size_t k) { return static_cast<int>(4 + w * static_cast<double>(k) / static_cast<double>(data_.size() - 1)); };
    const auto py = [&](double v) { return static_cast<int>(18 + h - h * std::min(1.0, v / top)); };
    dc.DrawLine(px(i - 1), py(data_[i - 1]), px(i), py(data_[i]));
  }
  char buf[96];
  std::snprintf(buf, sizeof buf, "time per step (ms), top %.3g ms", top);
  dc.DrawText(buf, 6, 2);
}

StatsPanel::StatsPanel(wxWindow* parent) : wxPanel(parent) {
  auto* sizer = new wxBoxSizer(wxVERTICAL);
  text_ = new wxStaticText(this, wxID_ANY, "no log open");
  text_->SetFont(wxFont(wxFontInfo(9).Family(wxFONTFAMILY_TELETYPE)));
  plot_ = new StepPlot(this);
  sizer->Add(text_, 0, wxALL | wxEXPAND, 6);
  sizer->Add(plot_, 1, wxALL | wxEXPAND, 6);
  SetSizer(sizer);
}

void StatsPanel::update(const MapSnapshot& s, const std::string& input, const std::string& ini) {
  const auto& st = s.stats;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "input      %s\nini        %s\n\nscans      %zu\nkeyframes  %zu\nclosures   %zu accepted, %zu rejected\n"
                "log time   %.1f s\nprocessing %.3f s\nreal time  %.0fx\nprogress   %.0f %%%s",
                input.c_str(), ini.c_str(), st.scans, st.keyframes, st.closures_accepted, st.closures_rejected, st.log_time_s,
                st.processing_s, st.processing_s > 0 ? st.log_time_s / st.processing_s : 0.0, 100 * st.progress,
                s.finished ? "  (finished)" : "");
  text_->SetLabel(buf);
  plot_->setData(st.step_ms);
  Layout();
}

ClosuresPanel::ClosuresPanel(wxWindow* parent) : wxPanel(parent) {
  auto* sizer = new wxBoxSizer(wxVERTICAL);
  list_ = new wxListCtrl(this, wxID_ANY, wxDefaultPosition, wxDefaultSize, wxLC_REPORT | wxLC_SINGLE_SEL);
  const char* cols[] = {"from", "to", "detector", "score", "result"};
  for (int i = 0; i < 5; ++i) list_->AppendColumn(cols[i]);
  sizer->Add(list_, 1, wxEXPAND | wxALL, 4);
  SetSizer(sizer);
  // A click (or Enter) on a row centres the map on that closure.
  const auto select = [this](wxListEvent& e) {
    const long row = e.GetIndex();
    if (!on_select || row < 0) return;
    unsigned long from = 0, to = 0;
    list_->GetItemText(row, 0).ToULong(&from);
    list_->GetItemText(row, 1).ToULong(&to);
    on_select(from, to);
  };
  list_->Bind(wxEVT_LIST_ITEM_SELECTED, select);
  list_->Bind(wxEVT_LIST_ITEM_ACTIVATED, select);
}

void ClosuresPanel::update(const MapSnapshot& s) {
  if (s.closures.size() < shown_) {  // restarted
    list_->DeleteAllItems();
    shown_ = 0;
  }
  for (; shown_ < s.closures.size(); ++shown_) {
    const auto& c = s.closures[shown_];
    const long row = list_->InsertItem(list_->GetItemCount(), std::to_string(c.from_keyframe));
    list_->SetItem(row, 1, std::to_string(c.to_keyframe));
    list_->SetItem(row, 2, slam::proposerName(c.detector));
    list_->SetItem(row, 3, wxString::Format("%.3f", c.score));
    list_->SetItem(row, 4, c.accepted ? wxString("accepted") : wxString("rejected: " + c.reason));
    list_->SetItemTextColour(row, c.accepted ? wxColour(20, 140, 50) : wxColour(170, 40, 150));
  }
}

CameraPanel::CameraPanel(wxWindow* parent) : wxPanel(parent) {
  auto* sizer = new wxBoxSizer(wxVERTICAL);
  auto* row = new wxBoxSizer(wxHORIZONTAL);
  auto* left = new wxBoxSizer(wxVERTICAL);
  auto* right = new wxBoxSizer(wxVERTICAL);
  current_caption_ = new wxStaticText(this, wxID_ANY, "no camera images in this log");
  matched_caption_ = new wxStaticText(this, wxID_ANY, "");
  current_ = new wxStaticBitmap(this, wxID_ANY, wxBitmap(160, 120));
  matched_ = new wxStaticBitmap(this, wxID_ANY, wxBitmap(160, 120));
  match_caption_ = new wxStaticText(this, wxID_ANY, "no Tree of Words proposal");
  left->Add(current_caption_, 0, wxBOTTOM, 3);
  left->Add(current_, 0);
  right->Add(matched_caption_, 0, wxBOTTOM, 3);
  right->Add(matched_, 0);
  row->Add(left, 1, wxALL, 4);
  row->Add(right, 1, wxALL, 4);
  sizer->Add(row, 0, wxEXPAND);
  sizer->Add(match_caption_, 0, wxALL, 6);
  SetSizer(sizer);
}

void CameraPanel::showFrame(const CameraFrame& f, wxStaticBitmap* bitmap, wxStaticText* caption, const io::CameraImage*& shown) {
  caption->SetLabel(f.caption);
  const int width = std::max(80, (GetClientSize().x - 24) / 2);  // two frames side by side
  if (f.image.get() == shown && width == shown_width_) return;
  shown = f.image.get();
  if (!f.image) {
    bitmap->SetBitmap(wxBitmap(width, width * 3 / 4));
    return;
  }
  const auto& im = *f.image;
  wxImage img(im.width, im.height);
  for (size_t i = 0; i < im.pixels->size(); ++i) {
    unsigned char* d = img.GetData() + 3 * i;
    d[0] = d[1] = d[2] = (*im.pixels)[i];
  }
  const double scale = static_cast<double>(width) / std::max(1, im.width);
  bitmap->SetBitmap(wxBitmap(img.Scale(width, std::max(1, static_cast<int>(im.height * scale)), wxIMAGE_QUALITY_BILINEAR)));
}

void CameraPanel::update(const CameraView& v) {
  if (!v.current.image && !v.match && !shown_current_) return;  // nothing yet: keep the hint
  const int width = std::max(80, (GetClientSize().x - 24) / 2);
  showFrame(v.current, current_, current_caption_, shown_current_);
  showFrame(v.matched, matched_, matched_caption_, shown_matched_);
  shown_width_ = width;
  match_caption_->SetLabel(v.match ? v.match_caption : "no recent Tree of Words proposal");
  if (v.match) match_caption_->SetForegroundColour(v.match->accepted ? wxColour(20, 140, 50) : wxColour(170, 40, 150));
  Layout();
}

KeyframePanel::KeyframePanel(wxWindow* parent) : wxPanel(parent) {
  auto* sizer = new wxBoxSizer(wxVERTICAL);
  text_ = new wxStaticText(this, wxID_ANY, "click a keyframe in the map to inspect it");
  text_->SetFont(wxFont(wxFontInfo(9).Family(wxFONTFAMILY_TELETYPE)));
  sizer->Add(text_, 0, wxALL | wxEXPAND, 6);
  SetSizer(sizer);
}

void KeyframePanel::show(const MapSnapshot& s, size_t index) {
  if (index >= s.keyframes.size()) return;
  const auto& k = s.keyframes[index];
  text_->SetLabel(
      wxString::Format("keyframe   %zu\ntime       %.3f s\nx          %.3f m\ny          %.3f m\n"
                       "heading    %.2f deg\nscan       %zu points",
                       k.index, k.timestamp, k.pose.x, k.pose.y, k.pose.phi * 180 / M_PI, k.points ? k.points->size() : 0));
  Layout();
}

}  // namespace urbanslam::gui
