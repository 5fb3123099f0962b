// `urbanslam eval-laser-loop MODEL DATA...`: held-out evaluation of a laser loop-closure model on
// logs with a reference trajectory — ROC of the boosted classifier and of the learning-free
// nearest-neighbour baseline, detection at 0 / 0.1 / 1 % false alarm, the rotation-invariance
// split (heading difference > 90° vs < 30°), and optionally a cross-validation curve on DATA.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "ArgParser.h"
#include "PairRuleOptions.h"
#include "Commands.h"
#include "urbanslam/common/AtomicFile.h"
#include "urbanslam/common/Error.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Progress.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/laser_loop/ClassifierModel.h"
#include "urbanslam/laser_loop/CrossValidation.h"
#include "urbanslam/laser_loop/NearestNeighbourBaseline.h"
#include "urbanslam/laser_loop/Reports.h"
#include "urbanslam/laser_loop/Roc.h"
#include "urbanslam/laser_loop/TrainingPairs.h"

namespace urbanslam::cli {

namespace {

constexpr double kFalseAlarms[] = {0.0, 0.001, 0.01};
const char* const kFaKeys[] = {"0", "0.001", "0.01"};

std::string pct(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", 100 * v);
  return buf;
}

}  // namespace

int evalLaserLoopCommand(const Argv& args) {
  ArgParser ap("urbanslam eval-laser-loop MODEL DATA... [--out DIR] [--json] [options]",
               "Evaluates a laser loop-closure model on logs that carry a reference trajectory (held-out data):\n"
               "all revisit pairs within --d-pos are positives, randomly drawn pairs beyond --d-neg negatives.\n"
               "Prints detection at 0 %, 0.1 % and 1 % false alarm for the model and for a learning-free\n"
               "nearest-neighbour baseline on the normalised feature vector, and the rotation test (positives\n"
               "with heading difference > 90° vs < 30°, at the 1 % false-alarm threshold), and the detection of\n"
               "same-side revisits (heading difference <= 90°: what a 180° scanner can see again) at 1 % and 0 %.");
  ap.addPositional("MODEL", "model file (share/laser_loop/default.model, or from train-laser-loop)");
  ap.addPositional("DATA", "logs with a reference trajectory", true, true);
  ap.addOption("out", "DIR", "write roc.csv, roc.png, features.csv (and cv.csv, cv.png with --cv-t-max) here");
  addPairRuleOptions(ap, "180", "20000", "positives per log (random subset beyond)");
  ap.addOption("negatives-per-positive", "R", "negatives drawn per positive", "10");
  ap.addOption("min-negatives", "N", "at least this many negatives per log (false-alarm resolution)", "20000");
  ap.addOption("factor", "F", "report the operating point at this factor (default: the model's)");
  ap.addOption("cv-t-max", "N", "also cross-validate AdaBoost on DATA for T = 1..N (0: off)", "0");
  ap.addOption("folds", "K", "folds for --cv-t-max", "10");
  ap.addOption("seed", "N", "random seed for pair sampling", "2");
  ap.addFlag("quiet", "no progress bars");
  ap.addFlag("json", "print the results as one JSON object");
  if (!ap.parse(args)) return 0;
  const bool quiet = ap.flag("quiet");
  const laser_loop::ClassifierModel model = laser_loop::loadModel(ap.positional("MODEL"));
  const double factor = ap.has("factor") ? ap.optionDouble("factor") : model.factor;

  laser_loop::ScanLoadOptions lo;
  lo.params = model.params;  // features exactly as the model was trained on
  lo.submap_window_m = model.submap_window_m;
  laser_loop::PairRules rules = pairRulesFrom(ap);
  rules.negatives_per_positive = ap.optionDouble("negatives-per-positive");
  rules.min_negatives = static_cast<size_t>(ap.optionInt("min-negatives"));

  common::Stopwatch clock;
  std::vector<laser_loop::ScanSet> sets;
  std::vector<laser_loop::LabelledPair> pairs;
  for (const auto& path : ap.positionals("DATA")) {
    common::ProgressBar bar("features " + std::filesystem::path(path).filename().string(), 1000, !quiet);
    lo.progress = [&bar](double f) { bar.update(static_cast<uint64_t>(f * 1000)); };
    sets.push_back(laser_loop::loadLabelledScans(path, lo));
    bar.finish();
    auto p = laser_loop::samplePairs(sets.back(), static_cast<uint32_t>(sets.size() - 1), rules);
    pairs.insert(pairs.end(), p.begin(), p.end());
  }
  // Baseline scaling from the evaluation scans themselves (no labels involved).
  std::vector<laser_loop::FeatureVector> all_features;
  for (const auto& s : sets)
    for (const auto& sc : s.scans) all_features.push_back(sc.features);
  const laser_loop::NearestNeighbourBaseline baseline(all_features);

  std::vector<double> pos, neg, bpos, bneg;
  std::vector<std::pair<double, double>> pos_heading;  // (score, |Δφ|) of positives
  for (const auto& p : pairs) {
    const auto& a = sets[p.set].scans[p.a].features;
    const auto& b = sets[p.set].scans[p.b].features;
    const double s = model.classifier.score(a, b), sb = baseline.score(a, b);
    if (p.match) {
      pos.push_back(s);
      bpos.push_back(sb);
      pos_heading.emplace_back(s, p.heading_diff_rad);
    } else {
      neg.push_back(s);
      bneg.push_back(sb);
    }
  }
  if (pos.empty() || neg.empty())
    throw common::InputError(std::string("no ") + (pos.empty() ? "positive" : "negative") +
                             " pairs in DATA: loosen --d-pos/--d-neg/--min-travel");
  const laser_loop::Roc roc(pos, neg), broc(bpos, bneg);

  // Rotation invariance (§7.4): detection of positives by heading difference, at the threshold
  // that gives 1 % (and 0 %) false alarm over all negatives.
  auto rotation = [&](double threshold) {
    size_t big = 0, big_hit = 0, small = 0, small_hit = 0;
    for (const auto& [s, dphi] : pos_heading) {
      if (dphi < 0) continue;
      if (dphi > M_PI / 2) {
        ++big;
        big_hit += s >= threshold;
      } else if (dphi < M_PI / 6) {
        ++small;
        small_hit += s >= threshold;
      }
    }
    common::Json r = common::Json::object();
    r["pairs_heading_gt_90"] = big;
    r["detection_heading_gt_90"] = big ? double(big_hit) / double(big) : 0.0;
    r["pairs_heading_lt_30"] = small;
    r["detection_heading_lt_30"] = small ? double(small_hit) / double(small) : 0.0;
    return r;
  };
  // A 180° scanner sees the same side of a place only on revisits within ±90° of heading: their
  // detection against every negative, the figure a front laser can be held to.
  std::vector<double> same_side_pos;
  for (const auto& [s, dphi] : pos_heading)
    if (dphi >= 0 && dphi <= M_PI / 2) same_side_pos.push_back(s);
  common::Json same_side = common::Json::object();
  same_side["positives"] = same_side_pos.size();
  if (!same_side_pos.empty()) {
    const laser_loop::Roc sroc(same_side_pos, neg);
    same_side["detection_at_fa_0.01"] = sroc.at(0.01).detection;
    same_side["detection_at_fa_0"] = sroc.at(0.0).detection;
  }
  size_t at_factor_det = 0, at_factor_fa = 0;
  for (double s : pos) at_factor_det += s >= factor;
  for (double s : neg) at_factor_fa += s >= factor;

  common::Json j = common::Json::object();
  j["model"] = ap.positional("MODEL");
  common::Json data = common::Json::array();
  for (const auto& s : sets) {
    common::Json d = common::Json::object();
    d["path"] = s.source;
    d["scans"] = s.scans.size();
    d["reference"] = s.reference_kind;
    data.push(d);
  }
  j["data"] = data;
  j["positives"] = pos.size();
  j["negatives"] = neg.size();
  for (int k = 0; k < 3; ++k) j[std::string("detection_at_fa_") + kFaKeys[k]] = roc.at(kFalseAlarms[k]).detection;
  for (int k = 0; k < 3; ++k) j[std::string("baseline_detection_at_fa_") + kFaKeys[k]] = broc.at(kFalseAlarms[k]).detection;
  j["auc"] = roc.auc();
  j["baseline_auc"] = broc.auc();
  j["factor"] = factor;
  j["detection_at_factor"] = double(at_factor_det) / double(pos.size());
  j["false_alarm_at_factor"] = double(at_factor_fa) / double(neg.size());
  j["rotation_at_fa_0.01"] = rotation(roc.at(0.01).threshold);
  j["rotation_at_fa_0"] = rotation(roc.at(0.0).threshold);
  j["same_side"] = same_side;

  if (ap.has("out")) {
    const std::filesystem::path dir = ap.option("out");
    std::filesystem::create_directories(dir);
    std::vector<laser_loop::NamedRoc> rocs = {{"adaboost", &roc}, {"nearest_neighbour", &broc}};
    laser_loop::writeRocCsv((dir / "roc.csv").string(), rocs);
    laser_loop::writeRocPng((dir / "roc.png").string(), rocs, "ROC " + std::filesystem::path(ap.positional("MODEL")).filename().string());
    j["roc_csv"] = (dir / "roc.csv").string();
    // Every scan's features with its reference pose, for inspecting what separates places.
    common::AtomicFile f((dir / "features.csv").string());
    f.stream() << "log,scan,timestamp,x,y,phi";
    for (int k = 0; k < laser_loop::kFeatureCount; ++k) f.stream() << "," << laser_loop::featureName(k);
    f.stream() << "\n";
    f.stream().precision(10);
    for (size_t si = 0; si < sets.size(); ++si)
      for (size_t i = 0; i < sets[si].scans.size(); ++i) {
        const auto& sc = sets[si].scans[i];
        f.stream() << si << "," << i << "," << sc.timestamp << "," << sc.pose.x << "," << sc.pose.y << ","
                   << (sc.has_heading ? sc.pose.phi : std::nan(""));
        for (double v : sc.features) f.stream() << "," << v;
        f.stream() << "\n";
      }
    f.commit();
  }
  const int cv_t = static_cast<int>(ap.optionInt("cv-t-max"));
  if (cv_t > 0) {
    // Balanced, as in training: every positive and as many negatives.
    std::vector<laser_loop::LabelledPair> balanced;
    size_t n_pos = 0, n_neg = 0;
    for (const auto& p : pairs) n_pos += p.match;
    for (const auto& p : pairs)
      if (p.match || n_neg < n_pos) {
        balanced.push_back(p);
        n_neg += !p.match;
      }
    const laser_loop::PairTable table = laser_loop::makePairTable(sets, balanced);
    laser_loop::CvOptions co;
    co.t_max = cv_t;
    co.folds = static_cast<int>(ap.optionInt("folds"));
    co.seed = rules.seed;
    const laser_loop::CvCurve cv = laser_loop::crossValidate(table, co);
    j["cv_chosen_T"] = cv.chosen_T;
    j["cv_total_rate_at_chosen_T"] = cv.total_rate[static_cast<size_t>(cv.chosen_T - 1)];
    if (ap.has("out")) {
      const std::filesystem::path dir = ap.option("out");
      laser_loop::writeCvCsv((dir / "cv.csv").string(), cv);
      laser_loop::writeCvPng((dir / "cv.png").string(), cv);
    }
  }
  j["seconds"] = clock.seconds();

  if (ap.flag("json")) {
    std::cout << j.dump() << "\n";
    return 0;
  }
  std::cout << "pairs: " << pos.size() << " positive, " << neg.size() << " negative (d_pos " << rules.d_pos_m << " m, d_neg "
            << rules.d_neg_m << " m, min travel " << rules.min_travel_m << " m)\n";
  std::cout << "false alarm   adaboost   nearest-neighbour baseline\n";
  for (int k = 0; k < 3; ++k) {
    char buf[120];
    std::snprintf(buf, sizeof buf, "%8.1f %%   %7.1f %%   %7.1f %%\n", 100 * kFalseAlarms[k], 100 * roc.at(kFalseAlarms[k]).detection,
                  100 * broc.at(kFalseAlarms[k]).detection);
    std::cout << buf;
  }
  std::cout << "AUC " << roc.auc() << " (baseline " << broc.auc() << ")\n";
  std::cout << "at factor " << factor << ": detection " << pct(double(at_factor_det) / double(pos.size())) << ", false alarm "
            << pct(double(at_factor_fa) / double(neg.size())) << "\n";
  const auto r = rotation(roc.at(0.01).threshold);
  std::cout << "rotation (at 1 % FA): heading difference > 90°: " << pct(r.at("detection_heading_gt_90").asNumber()) << " of "
            << static_cast<long>(r.at("pairs_heading_gt_90").asNumber()) << "; < 30°: " << pct(r.at("detection_heading_lt_30").asNumber())
            << " of " << static_cast<long>(r.at("pairs_heading_lt_30").asNumber()) << "\n";
  if (same_side.contains("detection_at_fa_0.01"))
    std::cout << "same side (heading difference <= 90°, " << same_side_pos.size() << " positives): detection at 1 % FA "
              << pct(same_side.at("detection_at_fa_0.01").asNumber()) << ", at 0 % FA " << pct(same_side.at("detection_at_fa_0").asNumber())
              << "\n";
  return 0;
}

}  // namespace urbanslam::cli
