#include "urbanslam/slam/Localizer.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "urbanslam/alignment/ScanModel.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Gating.h"
#include "urbanslam/esdf/PoseOps.h"
#include "urbanslam/slam/LocalSubmap.h"

namespace urbanslam::slam {

namespace {

constexpr double kDeg = M_PI / 180.0;

}  // namespace

LocalizerOptions localizerOptions(const PipelineOptions& map_options) {
  LocalizerOptions o;
  o.areas.matcher = priorMatcherOptions(map_options.local);
  o.covariance_scale = map_options.local.covariance_scale;
  // Place recognition searches whole heading circles over metres: a coarser grid whose returns
  // spread over a few cells keeps that search affordable and tolerant of the window's steps.
  o.areas.coarse.resolution_m = 0.1;
  o.areas.coarse.hit_sigma_m = 0.1;
  o.areas.coarse.miss_floor = map_options.local.miss_floor;
  o.areas.coarse.levels = 5;
  // Every level but the top at full resolution: the search's many blocks at levels 3 and 4
  // then get exact bounds, and most of them are pruned there instead of split (CSAIL's place
  // searches 33 % faster, the same poses; a few MB more per cached tile).
  o.areas.coarse.full_resolution_levels = 4;
  o.match_spacing_m = map_options.keyframes.min_translation_m;
  o.match_spacing_deg = map_options.keyframes.min_rotation_deg;
  o.images.image_loop = map_options.image_loop;
  return o;
}

const char* stateName(LocalizationState state) { return state == LocalizationState::Tracking ? "tracking" : "lost"; }

Localizer::Localizer(const Map& map, const PipelineOptions& map_options, LocalizerOptions options)
    : map_(map),
      options_(std::move(options)),
      motion_model_(map_options.motion.model),
      input_(map_options.input),
      motion_(map_options.motion, map_options.vehicle),
      areas_(map_, options_.areas),
      places_(map_, areas_, options_.places),
      following_(areas_, options_.places, options_.following),
      images_(map_, options_.images),
      monitor_(options_.monitor),
      matcher_(areas_.options().matcher),
      continuity_gate_(esdf::chi2Quantile(options_.continuity_probability, 2)),
      initial_gate_(esdf::chi2Quantile(0.999, 3)) {}

void Localizer::setInitialPose(const common::Pose2& pose) {
  const double s = options_.initial_sigma_xy_m, a = options_.initial_sigma_deg * kDeg;
  setPose(pose, Eigen::Vector3d(s * s, s * s, a * a).asDiagonal());
  state_ = LocalizationState::Tracking;
  monitor_.reset();
  consecutive_matches_ = 0;
  confirmed_ = false;
  initial_pose_ = true;
}

Eigen::Matrix3d withFloors(const Eigen::Matrix3d& cov, const LocalizerOptions& options) {
  return esdf::withDiagonalFloors(0.5 * (cov + cov.transpose()), options.min_sigma_xy_m, options.min_sigma_deg * kDeg);
}

void Localizer::setPose(const common::Pose2& pose, const Eigen::Matrix3d& cov) {
  pose_ = pose;
  cov_ = withFloors(cov, options_);
  have_pose_ = true;
}

std::optional<LocalizedScan> Localizer::add(const io::Measurement& m) {
  common::Stopwatch sw;
  ++stats_.measurements;
  std::optional<LocalizedScan> out;
  if (const auto* scan = std::get_if<io::LaserScan>(&m)) {
    ++stats_.scans;
    if (input_.accepts(scan->label)) out = onScan(*scan);
  } else if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
    ++stats_.odometry;
    if (motion_model_ != MotionOptions::Model::Steering) {
      motion_.addOdometry(*od);
      odom_prev_ = odom_last_;
      odom_last_ = *od;
      ++odom_readings_;
    }
  } else if (const auto* dr = std::get_if<io::DriveReading>(&m)) {
    if (motion_model_ != MotionOptions::Model::Odometry) motion_.addDrive(*dr);
  } else if (const auto* im = std::get_if<io::CameraImage>(&m)) {
    ++stats_.images;
    images_.addImage(*im);
  }
  stats_.wall_s += sw.seconds();
  stats_.references_built = areas_.referencesBuilt();
  stats_.coarse_grids_built = areas_.coarseGridsBuilt();
  return out;
}

common::Pose2 Localizer::odometryLead(double t) const {
  if (odom_readings_ < 2) return {};
  const double dt = odom_last_.timestamp - odom_prev_.timestamp;
  if (!(dt > 0)) return {};
  // Within one reading interval either way: beyond, the last rate says little.
  const double f = std::clamp((t - odom_last_.timestamp) / dt, -1.0, 1.0);
  const common::Pose2 step = common::between(odom_prev_.pose, odom_last_.pose);
  return {f * step.x, f * step.y, f * step.phi};
}

PlaceHypothesis Localizer::searchPlaces(const alignment::PointSet& points, const std::vector<PlaceSearchRegion>& regions) {
  common::Stopwatch sw;
  PlaceHypothesis h = places_.locate(points, matcher_, regions);
  stats_.place_search_wall_s += sw.seconds();
  ++stats_.place_searches;
  stats_.place_search_windows += static_cast<size_t>(h.candidates);
  return h;
}

std::optional<PlaceHypothesis> Localizer::searchImagePlaces(const alignment::PointSet& points, double t, double not_before) {
  if (!images_.mapHasImages()) return std::nullopt;
  const double r = options_.images.radius_m;
  const Eigen::Matrix2d circle = r * r * Eigen::Matrix2d::Identity();
  std::vector<PlaceSearchRegion> regions;
  for (const ImagePlace& p : images_.query(t, not_before)) {
    const common::Pose2& k = map_.keyframes()[p.keyframe].pose;
    regions.push_back({{k.x, k.y}, circle, 1.0});
  }
  if (regions.empty()) return std::nullopt;
  ++stats_.image_place_searches;
  return searchPlaces(points, regions);
}

void Localizer::takeFix(const PlaceHypothesis& h, bool confirmed, LocalizedScan& out) {
  setPose(h.pose, options_.covariance_scale * h.cov);
  state_ = LocalizationState::Tracking;
  confirmed_ = confirmed;
  consecutive_matches_ = 0;
  monitor_.reset();
  following_.stop();
  image_search_since_.reset();
  searched_ = false;
  out.map_fix = true;
  out.map_pose = pose_;
  out.map_cov = cov_;
  out.relocalised = true;
  out.matched = true;
  out.matched_fraction = h.matched_fraction;
  ++stats_.relocalisations;
}

void Localizer::follow(const PlaceHypothesis& h, const alignment::PointSet& points, double t, const std::optional<common::Pose2>& tracked) {
  if (h.places.empty()) return;
  std::vector<common::Pose2> places = h.places;
  if (tracked) places.push_back(*tracked);
  following_.start(places, places_.searchPoints(points), t);
  if (following_.active()) ++stats_.places_followed;
}

bool Localizer::placeSearchDue(double t) const {
  if (!searched_) return true;
  if (t - last_search_time_ < search_interval_s_) return false;
  const common::Pose2 moved = common::between(last_search_odometry_, motion_.odometryPose());
  return std::hypot(moved.x, moved.y) >= options_.relocalise_min_motion_m ||
         std::abs(moved.phi) >= options_.relocalise_min_rotation_deg * kDeg;
}

LocalizedScan Localizer::onScan(io::LaserScan scan) {
  input_.limitRanges(scan);
  ++stats_.scans_used;
  const double t = scan.timestamp;
  if (!have_scan_) stats_.first_timestamp = t;
  if (have_scan_ && state_ == LocalizationState::Lost) stats_.lost_s += std::max(0.0, t - last_scan_time_);
  stats_.last_timestamp = t;
  const alignment::PointSet points = alignment::pointSetFromScan(scan, areas_.options().scan_model, true);

  // Local SLAM's pose of this scan, when it follows a local trajectory that placed it, and
  // whether its view broke off (header).
  std::optional<common::Pose2> local_now;
  bool discontinuity = false;
  if (trajectory_)
    if (const auto newest = trajectory_->newestScan(); newest && newest->timestamp == t) {
      local_now = newest->pose;
      // A scan local SLAM did not try to match (too soon after the last) neither extends nor ends a run.
      if (const double f = trajectory_->scans().back().matched_fraction; f >= 0) {
        local_low_run_ = f < options_.discontinuity_matched_fraction ? local_low_run_ + 1 : 0;
        if (local_low_run_ == 1) view_break_t_ = t;
      }
      discontinuity = local_low_run_ == options_.discontinuity_scans && state_ == LocalizationState::Tracking;
    }

  // The prediction: the motion since the previous scan (local SLAM's, or the odometry's)
  // composed onto its pose, the covariance carried through the composition's Jacobians.
  common::Pose2 predicted = pose_;
  Eigen::Matrix3d predicted_cov = cov_;
  const common::Pose2 d = local_now && local_previous_
                              ? common::between(*local_previous_, *local_now)
                              : common::compose(common::compose(common::inverse(lead_), motion_.increment()), odometryLead(t));
  if (have_pose_) {
    const double c = std::cos(pose_.phi), s = std::sin(pose_.phi);
    Eigen::Matrix3d ja = Eigen::Matrix3d::Identity(), jd = Eigen::Matrix3d::Identity();
    ja(0, 2) = -s * d.x - c * d.y;
    ja(1, 2) = c * d.x - s * d.y;
    jd.topLeftCorner<2, 2>() << c, -s, s, c;
    predicted = common::compose(pose_, d);
    Eigen::Matrix3d q = motion_.covariance();
    if (local_now && local_previous_ && confirmed_ && trajectory_->keyframes().size() >= 2) {
      // A confirmed pose carried by local SLAM: local SLAM's own uncertainty, its newest keyframe
      // constraint's covariance in proportion to the share of a keyframe spacing moved.
      const double f = std::max(options_.match_spacing_m > 0 ? std::hypot(d.x, d.y) / options_.match_spacing_m : 1.0,
                                options_.match_spacing_deg > 0 ? std::abs(d.phi) / (options_.match_spacing_deg * kDeg) : 1.0);
      q = std::min(f, 1.0) * trajectory_->keyframes().back().cov;
    }
    predicted_cov = ja * cov_ * ja.transpose() + jd * q * jd.transpose();
  }

  LocalizedScan out;
  out.timestamp = t;
  // A confirmed pose that local SLAM carries is matched once per keyframe spacing of its travel.
  bool match_due = true;
  if (local_now && local_at_match_ && confirmed_) {
    const common::Pose2 moved = common::between(*local_at_match_, *local_now);
    match_due = std::hypot(moved.x, moved.y) >= options_.match_spacing_m || std::abs(moved.phi) >= options_.match_spacing_deg * kDeg;
  }
  bool initial_contradicted = false;
  bool replaced = false;
  if (following_.active() && following_.update(d, places_.searchPoints(points), t) == PlaceHypotheses::Outcome::Decided) {
    // The search's winner led every other place: the pose, unless it is the one tracked already.
    ++stats_.places_decided;
    const bool tracked_there =
        state_ == LocalizationState::Tracking && have_pose_ && !distinctPlaces(following_.winner(), predicted, options_.places);
    if (!tracked_there) {
      // Checked as a search's winner is, with no one-scan margin to its name: the strict share of
      // walls in free space applies.
      PlaceHypothesis h = places_.refine(points, following_.winner(), matcher_, PlaceHypothesis{});
      if (h.found) {
        if (state_ == LocalizationState::Tracking) ++stats_.poses_replaced;
        takeFix(h, false, out);
        replaced = true;
      }
    }
  }
  if (discontinuity && !replaced) {
    // The dead reckoning from the pose rules nothing out any more; the whole map is searched,
    // and the scan matched near the pose if the search does not replace it.
    ++stats_.discontinuities;
    confirmed_ = false;
    match_due = true;
    initial_pose_ = false;
    const PlaceHypothesis h = searchPlaces(points);
    if (h.found && distinctPlaces(h.pose, predicted, options_.places)) {
      takeFix(h, false, out);
      ++stats_.poses_replaced;
      replaced = true;
    } else {
      follow(h, points, t, predicted);
      if (!h.found && images_.mapHasImages()) image_search_since_ = view_break_t_;
    }
  }
  if (image_search_since_ && !replaced && state_ == LocalizationState::Tracking) {
    // The whole map's search left the discontinuity open: the first image since the view broke
    // off searches near the places it resembles (a fix there replaces the pose, as above).
    if (t - *image_search_since_ > options_.image_search_s) {
      image_search_since_.reset();
    } else if (const auto h = searchImagePlaces(points, t, *image_search_since_)) {
      image_search_since_.reset();
      if (h->found && distinctPlaces(h->pose, predicted, options_.places)) {
        takeFix(*h, false, out);
        ++stats_.poses_replaced;
        ++stats_.image_relocalisations;
        replaced = true;
      }
    }
  }
  if (replaced) {
    // Placed by the search.
  } else if (state_ == LocalizationState::Tracking && !match_due) {
    ++stats_.matches_skipped;
    setPose(predicted, predicted_cov);
  } else if (state_ == LocalizationState::Tracking) {
    local_at_match_ = local_now;
    const alignment::MatchReference* reference = areas_.reference(predicted.x, predicted.y);
    alignment::PriorMatchResult r;
    bool counted = false;  // the match's free-space counts were taken (a sample for the rates)
    if (reference) {
      alignment::PriorMatcherOptions o = matcher_;
      o.seen_through_rate = seen_through_.rate();
      o.seen_through_rate_displaced = seen_through_displaced_.rate();
      counted = !have_free_space_sample_ || std::abs(t - last_free_space_sample_) >= options_.free_space_sample_interval_s;
      o.count_free_space = counted;
      // The window covers the prediction's 3σ; the matcher's wider reach for a vehicle that
      // travelled far from the reference's origin does not apply in the map frame.
      const double sxy = std::sqrt(std::max(predicted_cov(0, 0), predicted_cov(1, 1)));
      o.max_search_window_m = std::clamp(3 * sxy, o.search_window_m, matcher_.max_search_window_m);
      r = alignment::matchWithPrior(*reference, points, predicted, predicted_cov, o);
    }
    out.matched_fraction = r.matchedFraction();
    if (reference && r.valid && out.matched_fraction >= options_.min_matched_fraction) {
      out.matched = true;
      if (++consecutive_matches_ >= options_.confirm_matches) confirmed_ = true, initial_pose_ = false;
      // The match's covariance: its posterior times the scale, floored, plus the spread where
      // the search and the refinement part (in doubt by that much, as in local SLAM's posterior,
      // LocalSlam.cpp: added after the floors and not scaled). Fused with the prediction's: a
      // match adds information, it cannot leave the pose less certain than the prediction was.
      // Taken alone, the spread along a direction the map hardly constrains (the far end of a
      // corridor) grew the covariance scan after scan, 2 cm to 46 cm in a second on Intel, until
      // a match jumped 0.4 m to a look-alike and back.
      const Eigen::Matrix3d match_cov = withFloors(options_.covariance_scale * r.cov, options_) + r.spread;
      setPose(r.pose, (predicted_cov.inverse() + match_cov.inverse()).inverse());
      out.map_fix = true;
      out.map_pose = r.pose;
      out.map_cov = match_cov;
      // The correction is the difference of two estimates of the pose, each with its own error:
      // the prediction's, and the match's against the map, which is at least the map's own
      // disagreement (the floors). Tested against the prediction's covariance alone, corrections
      // of an ordinary size failed the monitor's test and declared the pose lost while the
      // matches still explained the scan (FR079 tracked 50 % of its scans, 64 % with the floors
      // added). Only the floors: the rest of the match's covariance grows where the match is in
      // doubt (the spread), and would blunt the test where it matters (FR079 then tracked a pose
      // sliding 1 m and 10° off for 5 s before it was declared lost).
      const double fxy = options_.min_sigma_xy_m, fphi = options_.min_sigma_deg * kDeg;
      const Eigen::Matrix3d test_cov = predicted_cov + Eigen::Vector3d(fxy * fxy, fxy * fxy, fphi * fphi).asDiagonal().toDenseMatrix();
      const Eigen::Vector3d d(r.pose.x - predicted.x, r.pose.y - predicted.y, common::wrapToPi(r.pose.phi - predicted.phi));
      out.mahalanobis2 = d.dot(test_cov.inverse() * d);
      monitor_.addMatch(out.mahalanobis2);
      // A given initial pose states its uncertainty (initial_sigma_*): the first matches
      // correcting it beyond that (the 3-dof gate) say it was wrong, whatever follows. From a
      // wrong pose that happens to match (3 m and 40° off on the FR079 excerpt, each scan
      // explained at 65-70 %), local SLAM's motion carries the pose so consistently that ten
      // matches confirmed it, and the continuity test then kept the place search from the right
      // place for 8 s; the odometry's motion had the monitor give it up by chance, one scan later.
      if (initial_pose_ && out.mahalanobis2 > initial_gate_) initial_contradicted = true;
      if (counted && !r.odometry_outvoted) {
        seen_through_.add(r.in_view, r.seen_through);
        seen_through_displaced_.add(r.displaced_in_view, r.displaced_seen_through);
        have_free_space_sample_ = true;
        last_free_space_sample_ = t;
      }
    } else {
      ++stats_.matches_failed;
      monitor_.addFailure();
      consecutive_matches_ = 0;
      setPose(predicted, predicted_cov);
    }
    if (monitor_.lost() || initial_contradicted) {
      initial_pose_ = false;
      setPose(pose_, esdf::withDiagonalFloors(cov_, options_.lost_sigma_xy_m, options_.lost_sigma_deg * kDeg));
      state_ = LocalizationState::Lost;
      ++stats_.lost_events;
      searched_ = false;  // a place search right away
    }
  } else if (have_pose_) {
    setPose(predicted, predicted_cov);
  }

  motion_.reset();
  lead_ = odometryLead(t);
  if (state_ == LocalizationState::Lost && placeSearchDue(t)) {
    // A confirmed dead reckoning rules out every place beyond its gate (below): those are not
    // searched at all, which also leaves no search where the map never reached.
    std::optional<PlaceSearchRegion> region;
    const double k2 = options_.continuity_sigma_scale * options_.continuity_sigma_scale;
    if (confirmed_ && have_pose_) region = PlaceSearchRegion{{pose_.x, pose_.y}, k2 * cov_.topLeftCorner<2, 2>(), continuity_gate_};
    PlaceHypothesis h = searchPlaces(points, region ? std::vector<PlaceSearchRegion>{*region} : std::vector<PlaceSearchRegion>{});
    bool accepted = h.found;
    if (h.found && region) {
      const Eigen::Vector2d d(h.pose.x - pose_.x, h.pose.y - pose_.y);
      const Eigen::Matrix2d s = region->cov + options_.covariance_scale * h.cov.topLeftCorner<2, 2>();
      accepted = d.dot(s.inverse() * d) <= continuity_gate_;
      if (!accepted) ++stats_.fixes_rejected;
    }
    bool by_image = false;
    if (!h.found) {
      // No clear winner from the scan alone: the camera's image narrows the places. Not to the
      // dead reckoning's reach: that rules out the look-alikes of a scan, and an image that
      // resembles places beyond it says the vehicle is not where the dead reckoning has it (a
      // kidnapping local SLAM did not notice, as in a city's streets, whose scans continue
      // each other). The laser's winner must stand out among the image's places.
      if (auto hi = searchImagePlaces(points, t, -HUGE_VAL); hi && hi->found) {
        h = std::move(*hi);
        accepted = by_image = true;
        ++stats_.image_relocalisations;
      }
    }
    if (accepted) {
      // A fix that the confirmed dead reckoning admitted carries its confirmation on; one from
      // the whole map or the image's places has yet to earn it.
      takeFix(h, region.has_value() && !by_image, out);
    } else {
      search_interval_s_ =
          searched_ ? std::min(options_.relocalise_max_interval_s, 2 * search_interval_s_) : options_.relocalise_interval_s;
      searched_ = true;
      last_search_time_ = t;
      last_search_odometry_ = motion_.odometryPose();
    }
  }

  out.state = state_;
  out.has_pose = have_pose_;
  out.pose = pose_;
  out.cov = cov_;
  if (state_ == LocalizationState::Tracking) {
    ++stats_.tracking;
    if (stats_.first_fix_s < 0) stats_.first_fix_s = t - stats_.first_timestamp;
  } else {
    ++stats_.lost;
  }
  have_scan_ = true;
  last_scan_time_ = t;
  local_previous_ = local_now;
  return out;
}

}  // namespace urbanslam::slam
