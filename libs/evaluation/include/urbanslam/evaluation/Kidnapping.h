#pragma once
// A simulated kidnapping (the vehicle carried elsewhere without its odometry noticing), made from
// one log as bench/localize/kidnap.py makes it from a CARMEN log: the before_s seconds up to a
// time t1, then the after_s seconds from a later time t2, the second piece's timestamps moved back
// to follow t1 and its odometry moved to continue from t1's (the wheels felt nothing).
#include <vector>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/MapOutputs.h"
#include "urbanslam/io/Measurements.h"

namespace urbanslam::evaluation {

// `log`: measurements in time order (truth included or not: it is passed through, moved in time
// only). The spliced measurements, or none when the log has no odometry before t1 or after t2.
std::vector<io::Measurement> spliceKidnapping(const std::vector<io::Measurement>& log, double t1, double t2, double before_s,
                                              double after_s);

struct KidnapJump {
  size_t from = 0, to = 0;  // indices into the tracked poses: t1 at `from`, t2 at `to`
};

struct KidnapSchedule {
  int count = 5;
  double before_s = 10, after_s = 20;
  double gap_s = 30;      // t2 at least this long after t1 ...
  double min_jump_m = 5;  // ... and this far away
};

// kidnap.py's jumps: the starts spread evenly over the tracked poses with before_s of log before
// them and gap_s + after_s after; each start's end the first tracked pose gap_s later, min_jump_m
// away, with after_s of log after it. `tracked`: poses a localization tracked, in time order;
// [t_first, t_last]: the log's span.
std::vector<KidnapJump> pickKidnapJumps(const std::vector<io::StampedPose>& tracked, double t_first, double t_last,
                                        const KidnapSchedule& schedule);

}  // namespace urbanslam::evaluation
