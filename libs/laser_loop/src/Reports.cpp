#include "urbanslam/laser_loop/Reports.h"

#include <algorithm>
#include <cstdio>

#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/laser_loop/LinePlot.h"

namespace urbanslam::laser_loop {

namespace {
constexpr int kColors[] = {0xC03020, 0x2060D0, 0x20A040, 0x808080};
}

void writeCvCsv(const std::string& path, const CvCurve& cv) {
  common::AtomicFile f(path);
  auto& os = f.stream();
  os << "T,false_alarms,missed,fa_rate,md_rate,total_rate\n";
  char buf[160];
  for (size_t t = 0; t < cv.total_rate.size(); ++t) {
    std::snprintf(buf, sizeof buf, "%zu,%zu,%zu,%.6f,%.6f,%.6f\n", t + 1, cv.false_alarms[t], cv.missed[t], cv.fa_rate[t], cv.md_rate[t],
                  cv.total_rate[t]);
    os << buf;
  }
  f.commit();
}

void writeCvPng(const std::string& path, const CvCurve& cv) {
  std::vector<double> T;
  for (size_t t = 0; t < cv.total_rate.size(); ++t) T.push_back(static_cast<double>(t + 1));
  auto panel = [&](const std::string& title, const std::vector<double>& y, int color) {
    PlotPanel p;
    p.title = title;
    p.x_label = "T";
    p.y_label = "error";
    p.series.push_back({"", T, y, color});
    return p;
  };
  const std::string chosen = " (" + std::to_string(cv.folds) + "-fold, chosen T=" + std::to_string(cv.chosen_T) + ")";
  writePlotPng(path, {panel("FA error", cv.fa_rate, kColors[0]), panel("MD error", cv.md_rate, kColors[1]),
                      panel("Total error" + chosen, cv.total_rate, kColors[2])});
}

void writeRocCsv(const std::string& path, const std::vector<NamedRoc>& rocs) {
  common::AtomicFile f(path);
  auto& os = f.stream();
  os << "classifier,threshold,false_alarm,detection\n";
  char buf[200];
  for (const auto& r : rocs)
    for (const auto& p : r.roc->curve(5000)) {
      std::snprintf(buf, sizeof buf, "%s,%.9g,%.6f,%.6f\n", r.name.c_str(), p.threshold, p.false_alarm, p.detection);
      os << buf;
    }
  f.commit();
}

void writeRocPng(const std::string& path, const std::vector<NamedRoc>& rocs, const std::string& title) {
  PlotPanel lin, lg;
  lin.title = title;
  lin.x_label = "false alarm rate";
  lin.y_label = "detection rate";
  lin.x_min = 0, lin.x_max = 1, lin.y_min = 0, lin.y_max = 1;
  lg = lin;
  lg.title = "low false-alarm end (log axis)";
  lg.log_x = true;
  lg.x_min = 1e-4;
  int k = 0;
  for (const auto& r : rocs) {
    PlotSeries s{r.name, {}, {}, kColors[k++ % 4]};
    for (const auto& p : r.roc->curve(5000)) {
      s.x.push_back(p.false_alarm);
      s.y.push_back(p.detection);
    }
    lin.series.push_back(s);
    // On the log axis a zero false-alarm rate cannot be drawn: plot it at the axis floor.
    for (auto& x : s.x) x = std::max(x, 1e-4);
    lg.series.push_back(s);
  }
  writePlotPng(path, {lin, lg});
}

}  // namespace urbanslam::laser_loop
