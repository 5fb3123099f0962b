#include "PairRuleOptions.h"

#include <cmath>

namespace urbanslam::cli {

void addPairRuleOptions(ArgParser& ap, const char* max_heading_default_deg, const char* max_positives_default,
                        const char* max_positives_help) {
  ap.addOption("d-pos", "M", "positive pair: reference positions within this distance", "1.0");
  ap.addOption("d-neg", "M", "negative pair: reference positions farther apart than this", "3.0");
  ap.addOption("min-travel", "M", "positive pair: at least this much reference trajectory between the scans", "10");
  ap.addOption("max-heading-diff", "DEG", "positive pair: heading difference at most this (180: any heading)", max_heading_default_deg);
  ap.addOption("max-positives", "N", max_positives_help, max_positives_default);
}

laser_loop::PairRules pairRulesFrom(const ArgParser& ap) {
  laser_loop::PairRules rules;
  rules.d_pos_m = ap.optionDouble("d-pos");
  rules.d_neg_m = ap.optionDouble("d-neg");
  rules.min_travel_m = ap.optionDouble("min-travel");
  rules.max_positives = static_cast<size_t>(ap.optionInt("max-positives"));
  rules.max_heading_diff_rad = ap.optionDouble("max-heading-diff") * M_PI / 180;
  rules.seed = static_cast<uint64_t>(ap.optionInt("seed"));
  return rules;
}

}  // namespace urbanslam::cli
