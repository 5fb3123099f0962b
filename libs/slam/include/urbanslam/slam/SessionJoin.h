#pragma once
// Where another session's map lies in this one, with no prior: the other session's keyframe
// scans, one every probe_spacing_m of its path, are each searched for in the whole map by place
// recognition (PlaceRecognizer, as `localize` does at its start) in a map small enough for that
// exhaustive search (a building). In a larger one (a city, where a street's scan also matches
// all along the street within the search's range) and when the map uses the laser classifier,
// the classifier's best detections among the map's keyframes are aligned with the scan from no
// prior instead (CRF-match + ICP, then the loop closer's checks: residual, ambiguity, free
// space), and each that passes is a fix. Every fix gives a transform from the session's frame
// to the map's. One fix can be a look-alike place (a repeated facade, a corridor of identical
// doors, a street like another); the session's own trajectory is what tells, in two ways, and
// either joins:
//  - agreement: fixes of the right place agree on the transform, wrong ones scatter. The set of
//    agreeing fixes from the most scans joins when they are at least min_agreeing scans spread
//    over min_span_m of the session's path and at least min_agreeing_share of the scans that
//    gave a fix;
//  - confirmation: each fix is checked where it predicts the session's other scans to be: the
//    scans every check_spacing_m of the session's path within check_reach_m of it, placed by its
//    transform, are aligned locally with the map's keyframe there (PL-ICP from the prediction);
//    each lands where the fix puts it (it confirms the fix), elsewhere (it contradicts it) or
//    does not align. Under a wrong fix the scans around come to places that look otherwise: a
//    street's intersections and gaps fall elsewhere. The set of agreeing fixes that the most
//    scans support (its fixes' own and their confirmations) joins when those are at least
//    min_agreeing scans over min_span_m, at least min_agreeing_share of the scans that confirmed
//    or contradicted it, and one of its fixes has min_confirmations, most of its checks.
// In both, no other set of fixes that disagrees with the join may have min_agreeing scans (two
// places that both explain the session: no join rather than a wrong one). The search stops at
// the first fix that makes the join: a log being mapped is joined as early as it can be (the
// checks of its fixes go on as it grows), and a finished session is searched coarse to fine.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/common/Pose2.h"
#include "urbanslam/io/LaserScan.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/Proposer.h"

namespace urbanslam::slam {

struct SessionJoinOptions {
  double probe_spacing_m = 2.0;  // one place search per this much of the session's path
  // Two fixes agree when one's transform puts the other's keyframe within agree_m plus
  // agree_per_m times the session's path between them (its drift) of where the other was found,
  // and its heading within agree_deg.
  double agree_m = 1.0;
  double agree_per_m = 0.02;
  double agree_deg = 5.0;
  int min_agreeing = 4;
  double min_span_m = 6.0;  // of the session's path between the first and last agreeing fix
  double min_agreeing_share = 0.5;
  // The exhaustive place search only in maps of at most this many search windows (PlaceRecognizer:
  // one per 2 m cell the map's keyframes visited): its time grows faster than the map.
  int place_search_max_windows = 150;
  // Beyond that: the laser classifier's best detections aligned per scan, one per place (the
  // map's [loop_closure] search_radius_m apart); 0: none. Used when the map's [loop_closure]
  // detector is laser.
  int appearance_candidates = 3;
  // The checks of each fix along the session's path: a scan every check_spacing_m within
  // check_reach_m before and after it, aligned with the map's keyframe nearest to where the fix
  // puts it (within the map's [loop_closure] search_radius_m and facing within check_max_deg:
  // one that sees the same side).
  double check_spacing_m = 5.0;
  double check_reach_m = 50.0;
  double check_max_deg = 45.0;
  // A join by confirmation needs a fix that this many of the session's scans confirm, and at
  // least min_agreeing_share of the scans checked against it (those that did not align
  // included). In a city of look-alike streets a wrong fix can have 3 or 4 confirmations, but of
  // 14 to 17 scans checked (the rest do not align there); a right one has 10 to 18 of 12 to 18.
  int min_confirmations = 3;
};

struct SessionFix {
  size_t keyframe = 0;                                // the session's keyframe
  common::Pose2 pose;                                 // where it was found, map frame
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();  // place: as the localizer takes a match; laser: as a loop closure an alignment
  Proposer detector = Proposer::Place;                // who found it: the place search, or the classifier and alignment (Laser)
  double margin_per_point = 0;                        // place: the search's margin; laser: the classifier's
  common::Pose2 transform;                            // session frame -> map frame, from this fix
  std::vector<size_t> confirmed;                      // the session's keyframes whose scans landed where this fix puts them
  std::vector<size_t> contradicted;                   // ... and those that did not, where the map has a keyframe to tell
  std::vector<size_t> unaligned;                      // ... and those that did not align with the map's scan there
  bool checked_back = false;                          // the earlier scans checked (by the fix's first check)
  size_t checked_to = 0;                              // the last of the later keyframes looked at
  double next_check_m = 0;                            // the session's path at which the next later scan is checked
};

struct SessionJoin {
  bool joined = false;
  std::string reason;       // why not
  common::Pose2 transform;  // session frame -> map frame (the agreeing fix's nearest to the session's start)
  // Its uncertainty at the session's first keyframe: the agreement's tolerance, grown by the
  // drift allowance over the session's path from there to that fix.
  Eigen::Matrix3d transform_cov = Eigen::Matrix3d::Identity();
  size_t probes = 0;               // place searches made
  std::vector<SessionFix> fixes;   // every fix found
  std::vector<size_t> agreeing;    // indices into fixes: the join's
  size_t agreeing_scans = 0;       // the session's scans that support them (their own and their confirmations)
  size_t contradicting_scans = 0;  // the session's scans checked against them that did not land where they say
  size_t rival = 0;                // the session's scans of the largest set of fixes that disagrees with the join
  SessionJoinOptions options;      // what it was judged by
};

// Whether `claimed`, a place in the map for the session's keyframe `keyframe` (a closure's), is
// where one of the join's agreeing fixes puts it, as two fixes must agree: within agree_m plus
// agree_per_m times the session's path between the keyframe and that fix (its drift), and
// agree_deg (SessionJoinOptions). `pose`: the keyframe's pose in the session's frame; `path_m`:
// the session's path length at each of its keyframes (std::out_of_range for a keyframe beyond it).
bool agreesWithJoin(const SessionJoin& join, size_t keyframe, const common::Pose2& pose, const std::vector<double>& path_m,
                    const common::Pose2& claimed);

// The covariance a join's fix enters the map with where its two keyframes' scans cannot measure
// it (GlobalSlam::addPlaceFix): a place search's no tighter than the join's agreement (agree_m,
// agree_deg), which is all the join checked of it; a search settles to its grid's reach, and
// on ACES one settled 1.2 m along a corridor with a posterior of 2 cm. A classifier's detection
// is an alignment already: its covariance as it is.
Eigen::Matrix3d fixCovariance(const SessionFix& fix, const SessionJoinOptions& options);

// The search kept up to date while the session grows (a run that joins a map as it goes):
// update() probes the keyframes added since the last call.
class SessionJoiner {
 public:
  // `map_options`: the map's options (its matcher and scan model). The map must outlive this.
  SessionJoiner(const Map& map, const PipelineOptions& map_options, SessionJoinOptions options = {});
  ~SessionJoiner();
  // Probes the session's keyframes not seen yet; returns the join as it stands. `progress`
  // (optional) is told the share of the session's keyframes seen.
  const SessionJoin& update(const Map& session, const std::function<void(double)>& progress = {});
  // A whole session at once, the probes coarse to fine along its path, until it is joined.
  const SessionJoin& searchAll(const Map& session, const std::function<void(double)>& progress = {});
  const SessionJoin& join() const { return join_; }

 private:
  void decide(const Map& session);
  void extendPath(const Map& session);
  bool probe(const Map& session, size_t keyframe);                   // true: joined now
  void appearanceFixes(size_t keyframe, const io::LaserScan& scan);  // the classifier's, where the place search found none
  size_t check(const Map& session, SessionFix& fix);                 // its checks on the scans not looked at yet; how many
  bool addFixes(const Map& session, size_t first);                   // checks fixes[first..] and decides; true: joined now

  struct Search;
  std::unique_ptr<Search> search_;
  SessionJoinOptions options_;
  SessionJoin join_;
  size_t seen_ = 0;           // session keyframes looked at
  std::vector<double> path_;  // the session's path length at each keyframe seen
  double next_probe_m_ = 0;
};

// The whole session at once (SessionJoiner::searchAll).
SessionJoin findSessionJoin(const Map& map, const PipelineOptions& map_options, const Map& session, const SessionJoinOptions& options = {},
                            const std::function<void(double)>& progress = {});

}  // namespace urbanslam::slam
