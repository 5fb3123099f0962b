#include "Commands.h"

namespace urbanslam::cli {

const std::vector<Command>& commands() {
  static const std::vector<Command> all = {
      {"run", "build a map and trajectory from a log (the main job)", runCommand},
      {"localize", "track a log's vehicle in the map of an earlier run (the map unchanged)", localizeCommand},
      {"merge", "join the maps of separate runs into one by place recognition, optimised together", mergeCommand},
      {"convert", "write any supported log as an MRPT rawlog", convertCommand},
      {"eval", "accuracy of a run: relations, ATE/RPE, true/false loop closures", evalCommand},
      {"graph", "feed a g2o/TORO pose graph to the ESDF incrementally; chi2 and timings", graphCommand},
      {"align", "align two laser scans of a log (ICP, PL-ICP, CRF-match, CRF+ICP) with covariance", alignCommand},
      {"simulate", "drive a car through a generated city: laser, odometry, GPS and ground truth", simulateCommand},
      {"check-ini", "validate an ini file and print the resolved configuration", checkIniCommand},
      {"train-laser-loop", "train the laser loop-closure classifier (AdaBoost) from logs with a reference", trainLaserLoopCommand},
      {"eval-laser-loop", "ROC of a laser loop-closure model on held-out logs", evalLaserLoopCommand},
      {"build-vocabulary", "train a Tree of Words image vocabulary offline", buildVocabularyCommand},
      {"eval-image-loop", "precision-recall of image loop detection against ground truth", evalImageLoopCommand},
  };
  return all;
}

}  // namespace urbanslam::cli
