#pragma once
// The evaluation of one run folder (`urbanslam eval`): the relation metric on the run's nodes and
// on its odometry-time trajectory, ATE/RPE against a reference, loop closures against either, the
// scans' evidence on each disputed closure, and, against a simulated drive, the map's distance to
// the true walls and the share of revisits closed. The report is the JSON `eval` prints.
#include <optional>
#include <string>
#include <vector>

#include "urbanslam/common/Json.h"
#include "urbanslam/io/MapOutputs.h"

namespace urbanslam::evaluation {

struct RunReportOptions {
  std::string run_dir;    // the output folder of `urbanslam run`
  std::string relations;  // Freiburg relations file; empty: none
  std::string reference;  // TUM file or a log that carries a reference; empty: RUN_DIR/reference.tum for the relations' time base
  std::string truth_dir;  // a simulated drive's folder (its truth.tum is the reference); empty: none
  std::string scans;      // TUM file whose times are the scans for the relations' breakdown; empty: the run's own
  std::optional<double> time_offset_s;  // added to the run's times for the relations; none: found
  double max_gap_s = 0;                 // a relation is used only where the trajectory's poses are this close; 0: any gap
  double loop_tolerance_m = 0.5;        // a closure is true within this of the reference ...
  double loop_tolerance_deg = 5;        // ... and this
};

struct RunReport {
  common::Json json;
  // Against a reference: the reference, the estimate aligned onto it, and the position error over time.
  std::vector<io::StampedPose> reference, aligned;
  std::vector<double> times, errors_m;
};

// Bad input (a missing or empty trajectory, no overlap with the reference or the relations) is a
// common::InputError naming the file.
RunReport evaluateRun(const RunReportOptions& options);

}  // namespace urbanslam::evaluation
