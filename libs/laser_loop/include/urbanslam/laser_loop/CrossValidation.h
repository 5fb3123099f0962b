#pragma once
// Tenfold cross-validation over the number of boosting rounds T (thesis §3.2.4): the pairs are
// shuffled and split into `folds` subsets; for each subset AdaBoost is trained on the others and
// validated on it, and the validation results of all subsets are pooled. Because AdaBoost is
// incremental, the classifier after T rounds is the first T stumps of one run to T_n, so one run
// per fold yields the whole curve T = 1..T_n.
//
// Errors as in Figure 3.5: false-alarm rate (non-matching pairs called matching, over all
// non-matching pairs), missed-detection rate (over matching pairs) and total error (FA + MD
// over all pairs). The chosen T is the smallest T whose pooled total error is within
// `tolerance` of the minimum over 1..T_n — the thesis picked T = 50 from the flattening curve
// by eye; this makes the same choice reproducible.
#include <cstdint>
#include <functional>
#include <vector>

#include "urbanslam/laser_loop/WeakClassifier.h"

namespace urbanslam::laser_loop {

struct CvOptions {
  int folds = 10;
  int t_max = 100;
  double factor = 0.5;
  double tolerance = 0.002;
  uint64_t seed = 1;
  std::function<void(int fold)> progress;  // called after each fold
};

struct CvCurve {
  std::vector<size_t> false_alarms, missed;  // pooled counts, index T−1
  std::vector<double> fa_rate, md_rate, total_rate;
  size_t n_pos = 0, n_neg = 0;
  int chosen_T = 0;
  int folds = 0;
};

CvCurve crossValidate(const PairTable& data, const CvOptions& options);

}  // namespace urbanslam::laser_loop
