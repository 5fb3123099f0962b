#pragma once
// Where in a frozen map a scan was taken, with no idea of the pose beforehand (global
// localization): the scan is searched exhaustively — every heading, every position within a
// window — around each place the map's keyframes visited (one window per cell of
// candidate_spacing_m), on the coarse likelihood grids (correlative branch and bound), and the
// best pose is refined by the local matcher on the fine reference. The answer is accepted only
// when it is a clear winner: its scan log-likelihood beats that of the best pose at any other
// place by a margin per point (a corridor's look-alike doors, a symmetric room, a place the map
// has not seen: no answer rather than a wrong one), the refined match explains most points, and
// few of them stand where the other side's beams passed through.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "urbanslam/alignment/PointSet.h"
#include "urbanslam/alignment/PriorScanMatcher.h"
#include "urbanslam/common/Pose2.h"
#include "urbanslam/slam/Map.h"
#include "urbanslam/slam/MapAreas.h"

namespace urbanslam::slam {

struct PlaceRecognitionOptions {
  double candidate_spacing_m = 2.0;  // one search window per keyframe cell this wide ...
  double window_overlap_m = 0.75;    // ... reaching this far into a neighbouring cell that has no window of its own
  double voxel_m = 0.3;              // the scan thinned to one point per voxel for the search
  double max_range_m = 25.0;         // farther returns left out of the search (the grids reach about this far)
  int min_points = 20;               // fewer thinned points: too little to recognise a place
  // The winner's log-likelihood over the best pose at another place (farther than distinct_m or
  // distinct_deg), per thinned point [nats]; an unexplained point costs about 3 nats.
  double min_margin_per_point = 0.3;
  double distinct_m = 1.0;
  double distinct_deg = 20.0;
  double min_matched_fraction = 0.6;  // of the scan's points within the matcher's gate after refinement
  // Of the points in view of the other side (scan points in the map scans' beams, map points in
  // the scan's), the share that lies where those beams passed through: at the right pose a few
  // percent (people, glass; about 3 % on FR079), at a wrong one that looks alike, walls stand
  // in open space (8-12 % measured for Intel scans placed in the FR079 map).
  double max_seen_through_share = 0.06;
  // A winner that beats every other place by clear_margin_per_point is allowed up to this share:
  // no place of the map looks like it, and the walls it has in free space are what changed since
  // the map was made (people, doors: 6-13 % at the right pose after a simulated kidnapping in
  // the raw benchmark logs, whose margins were 0.75-1.1 nats per point).
  double clear_margin_per_point = 0.6;
  double max_seen_through_share_clear = 0.15;
  double refine_sigma_m = 0.2;  // the coarse pose's uncertainty as the refinement's prior
  double refine_sigma_deg = 3.0;
};

// Two poses are different places: farther apart than distinct_m, or turned by more than
// distinct_deg.
bool distinctPlaces(const common::Pose2& a, const common::Pose2& b, const PlaceRecognitionOptions& options);

// Where the scan may have been taken, when something other than the scan says so: a position
// with its covariance and a chi-square gate (the dead reckoning), or a circle about a keyframe
// whose image looks like the camera's (cov r² I, gate 1). Only the windows that reach into one
// of a search's regions are searched, and the winner must stand out among those only; the rest
// of the map is ruled out.
struct PlaceSearchRegion {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity();
  double gate = 0;  // on d' cov⁻¹ d
};

struct PlaceHypothesis {
  bool found = false;
  std::string reason;  // why not found
  common::Pose2 pose;  // refined, map frame
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  double score = 0, second_score = 0;  // coarse scan log-likelihoods of the winner and of the best elsewhere
  double margin_per_point = 0;
  double matched_fraction = 0;
  double seen_through_share = 0;
  int points = 0, candidates = 0, nodes = 0;
  // Ambiguous: the distinct places within the margin of the winner (each the best pose of its
  // window), the winner first, the rest best first. Following them over the next scans can tell
  // them apart (PlaceHypotheses.h).
  std::vector<common::Pose2> places;
};

class PlaceRecognizer {
 public:
  PlaceRecognizer(const Map& map, MapAreas& areas, PlaceRecognitionOptions options);
  // `scan`: the scan's points in the vehicle frame. `matcher`: the local matcher's options for
  // the refinement. `regions`: search only within reach of one of them (none: the whole map).
  PlaceHypothesis locate(const alignment::PointSet& scan, const alignment::PriorMatcherOptions& matcher,
                         const std::vector<PlaceSearchRegion>& regions = {});
  size_t candidates() const { return centres_.size(); }
  // The scan's points a search scores: near returns only (farther ones fall outside the grids),
  // one per voxel (roughly independent).
  std::vector<Eigen::Vector2d> searchPoints(const alignment::PointSet& scan) const;
  // A coarse pose refined on the fine reference and checked (matched share, walls in the other
  // side's free space): `h` found, or the reason it is not.
  PlaceHypothesis refine(const alignment::PointSet& scan, const common::Pose2& coarse, const alignment::PriorMatcherOptions& matcher,
                         PlaceHypothesis h);

 private:
  MapAreas& areas_;
  PlaceRecognitionOptions options_;
  std::vector<Eigen::Vector2d> centres_;  // window centres (cell centres), grouped by tile
};

}  // namespace urbanslam::slam
