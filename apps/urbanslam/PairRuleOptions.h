#pragma once
// The pair-labelling options shared by train-laser-loop and eval-laser-loop: one declaration,
// so training and evaluation cannot drift apart in what "same place" means.
#include "ArgParser.h"
#include "urbanslam/laser_loop/TrainingPairs.h"

namespace urbanslam::cli {

// Declares --d-pos, --d-neg, --min-travel, --max-heading-diff and --max-positives.
void addPairRuleOptions(ArgParser& ap, const char* max_heading_default_deg, const char* max_positives_default,
                        const char* max_positives_help);

// The rules from those options (+ --seed); the caller sets the sampling fields it owns.
laser_loop::PairRules pairRulesFrom(const ArgParser& ap);

}  // namespace urbanslam::cli
