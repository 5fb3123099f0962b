#pragma once
// The evaluation figures as files: cross-validation curves (Figure 3.5: FA, MD and total error
// against T) and ROC curves, each as CSV (the numbers) and PNG (a quick look). All atomic.
#include <string>
#include <vector>

#include "urbanslam/laser_loop/CrossValidation.h"
#include "urbanslam/laser_loop/Roc.h"

namespace urbanslam::laser_loop {

// Columns: T, false_alarms, missed, fa_rate, md_rate, total_rate.
void writeCvCsv(const std::string& path, const CvCurve& cv);
// Three panels as in Figure 3.5, with the chosen T marked in the title.
void writeCvPng(const std::string& path, const CvCurve& cv);

struct NamedRoc {
  std::string name;
  const Roc* roc = nullptr;
};
// Columns: classifier, threshold, false_alarm, detection.
void writeRocCsv(const std::string& path, const std::vector<NamedRoc>& rocs);
// Two panels: linear false-alarm axis, and logarithmic from 1e-4 (the low-FA end that matters).
void writeRocPng(const std::string& path, const std::vector<NamedRoc>& rocs, const std::string& title);

}  // namespace urbanslam::laser_loop
