#include "urbanslam/laser_loop/CrossValidation.h"

#include <algorithm>
#include <numeric>
#include <random>

#include "urbanslam/common/Error.h"
#include "urbanslam/laser_loop/AdaBoost.h"

namespace urbanslam::laser_loop {

CvCurve crossValidate(const PairTable& data, const CvOptions& opt) {
  if (opt.folds < 2) throw common::InputError("cross-validation needs at least 2 folds");
  if (opt.t_max < 1) throw common::InputError("cross-validation needs T_n >= 1");
  const size_t n = data.size();
  if (n < static_cast<size_t>(opt.folds)) throw common::InputError("fewer pairs than folds");
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::mt19937_64 rng(opt.seed);
  std::shuffle(order.begin(), order.end(), rng);

  CvCurve cv;
  cv.folds = opt.folds;
  const size_t T = static_cast<size_t>(opt.t_max);
  cv.false_alarms.assign(T, 0);
  cv.missed.assign(T, 0);
  for (uint32_t i : order) (data.y[i] ? cv.n_pos : cv.n_neg)++;

  for (int k = 0; k < opt.folds; ++k) {
    const size_t lo = n * static_cast<size_t>(k) / static_cast<size_t>(opt.folds);
    const size_t hi = n * static_cast<size_t>(k + 1) / static_cast<size_t>(opt.folds);
    std::vector<uint32_t> train, val(order.begin() + static_cast<long>(lo), order.begin() + static_cast<long>(hi));
    train.reserve(n - val.size());
    train.insert(train.end(), order.begin(), order.begin() + static_cast<long>(lo));
    train.insert(train.end(), order.begin() + static_cast<long>(hi), order.end());
    AdaBoostTrainer trainer(data, train);
    trainer.run(opt.t_max);
    const auto& stumps = trainer.classifier().stumps();
    for (uint32_t i : val) {
      double vote = 0, total = 0;
      bool decided = false;
      for (size_t t = 0; t < T; ++t) {
        // Training may stop early (perfect or chance-level stump): the classifier stays as is.
        if (t < stumps.size()) {
          const auto& s = stumps[t];
          total += s.alpha;
          if (s.stump.match(data.c[s.stump.comparison][i])) vote += s.alpha;
          decided = vote >= opt.factor * total && total > 0;
        }
        if (data.y[i] && !decided) ++cv.missed[t];
        if (!data.y[i] && decided) ++cv.false_alarms[t];
      }
    }
    if (opt.progress) opt.progress(k + 1);
  }
  double best = 2;
  for (size_t t = 0; t < T; ++t) {
    cv.fa_rate.push_back(cv.n_neg ? double(cv.false_alarms[t]) / double(cv.n_neg) : 0.0);
    cv.md_rate.push_back(cv.n_pos ? double(cv.missed[t]) / double(cv.n_pos) : 0.0);
    cv.total_rate.push_back(double(cv.false_alarms[t] + cv.missed[t]) / double(n));
    best = std::min(best, cv.total_rate.back());
  }
  for (size_t t = 0; t < T; ++t)
    if (cv.total_rate[t] <= best + opt.tolerance) {
      cv.chosen_T = static_cast<int>(t + 1);
      break;
    }
  return cv;
}

}  // namespace urbanslam::laser_loop
