#include "urbanslam/slam/Pipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/esdf/Recovery.h"
#include "urbanslam/slam/CameraMotion.h"
#include "urbanslam/vision_loop/LoopDetector.h"

namespace urbanslam::slam {

namespace {

// The filter behind the map (none in dead reckoning).
std::unique_ptr<esdf::Esdf> makeFilter(const PipelineOptions& options) {
  if (options.estimator.type != EstimatorOptions::Type::Esdf) return nullptr;
  esdf::EsdfOptions eo;
  eo.relinearise = options.estimator.relinearise;
  eo.chi2_gate_probability = options.loop_closure.chi2_gate_probability;
  eo.gate_covariance = esdf::CovarianceMode::Exact;
  return std::make_unique<esdf::Esdf>(eo);
}

}  // namespace

Pipeline::Pipeline(PipelineOptions options)
    : options_(std::move(options)),
      input_(options_.input),
      map_(makeFilter(options_), std::max(1.0, options_.loop_closure.search_radius_m)),
      local_(options_),
      global_(options_, map_, stats_, observers_),
      images_(options_.loop_closure.image_max_offset_s) {}

Pipeline::~Pipeline() = default;

void PipelineStats::recordStep(double ms, size_t keyframes) {
  step_ms.push_back(ms);
  size_t decade = 0;
  for (size_t n = keyframes; n >= 10; n /= 10) ++decade;
  if (step_ms_by_decade.size() <= decade) step_ms_by_decade.resize(decade + 1);
  step_ms_by_decade[decade].push_back(ms);
}

void Pipeline::addObserver(PipelineObserver* observer) { observers_.push_back(observer); }

void Pipeline::setCandidateScorer(CandidateScorer scorer, std::string name) {
  global_.setCandidateScorer(std::move(scorer), std::move(name));
}

bool Pipeline::step(io::DataSource& source) {
  // Processing time (reading included) accumulates here, so a paused GUI run reports the same
  // real-time factor as a batch run.
  common::Stopwatch sw;
  bool more = false;
  try {
    more = stepOnce(source);
  } catch (const esdf::NotPositiveDefinite& e) {
    // Values that are each in range can still be too extreme together for the filter's
    // arithmetic (an odometry jump of thousands of km): that is the log's fault, not a bug.
    std::ostringstream where;
    where.precision(15);
    where << source.path() << ": measurement " << stats_.measurements << " (t = " << stats_.last_timestamp << " s)";
    throw common::InputError(where.str() + ": the filter's " + e.what() +
                             " after it (a pose, odometry or range far out of line with the rest of the log?)");
  }
  stats_.wall_s += sw.seconds();
  return more;
}

bool Pipeline::stepOnce(io::DataSource& source) {
  io::Measurement m;
  if (!source.next(m)) return false;
  ++stats_.measurements;
  const double t = io::timestampOf(m);
  if (!have_first_ts_) {
    stats_.first_timestamp = t;
    have_first_ts_ = true;
  }
  stats_.last_timestamp = t;
  if (auto* scan = std::get_if<io::LaserScan>(&m)) {
    ++stats_.scans;
    onScan(std::move(*scan), source.progress());
  } else if (const auto* od = std::get_if<io::OdometryReading>(&m)) {
    ++stats_.odometry;
    if (local_.addOdometry(*od)) map_.addOdometry(od->timestamp, local_.motion().odometryPose());
  } else if (const auto* dr = std::get_if<io::DriveReading>(&m)) {
    ++stats_.drive;
    if (local_.addDrive(*dr)) map_.addOdometry(dr->timestamp, local_.motion().odometryPose());
  } else if (const auto* ref = std::get_if<io::ReferencePose>(&m)) {
    ++stats_.reference;
    reference_.push_back({ref->timestamp, ref->pose});
  } else if (const auto* img = std::get_if<io::CameraImage>(&m)) {
    ++stats_.images;
    for (auto* o : observers_) o->onImage(*img);
    onCameraImage(*img, source.progress());
  } else if (std::holds_alternative<io::GpsFix>(m)) {
    ++stats_.gps;
  }
  return true;
}

void Pipeline::run(io::DataSource& source) {
  runInput(source);
  finish(source);
}

void Pipeline::runInput(io::DataSource& source) {
  while (step(source)) {
  }
}

void Pipeline::finish(const io::DataSource& source) {
  try {
    finish();
  } catch (const esdf::NotPositiveDefinite& e) {
    throw common::InputError(source.path() + ": the filter's " + e.what() +
                             " at the end of the log (a pose, odometry or range far out of line with the rest?)");
  }
}

void Pipeline::finish() {
  finished_ = true;
  common::Stopwatch sw;
  if (auto last = images_.finish()) attachImage(*last);  // the last keyframe's image is final now
  global_.finish();
  stats_.wall_s += sw.seconds();
  stats_.keyframes = map_.size();
  for (auto* o : observers_) o->onFinished();
}

void Pipeline::onScan(io::LaserScan scan, double progress) {
  common::Stopwatch sw;
  if (!input_.accepts(scan.label)) return;
  ++stats_.scans_used;
  input_.limitRanges(scan);
  if (local_.isKeyframe(map_)) {
    common::Stopwatch kw;
    addKeyframe(std::move(scan));
    stats_.keyframe_ms.push_back(kw.milliseconds());
  } else if (const auto anchor = local_.placeScan(scan, map_)) {
    ++stats_.scans_anchored;
    map_.addAnchor(*anchor);
  }
  const double ms = sw.milliseconds();
  stats_.recordStep(ms, map_.size());
  StepEvent ev{stats_.scans_used, map_.size(), stats_.last_timestamp, ms, progress};
  for (auto* o : observers_) o->onStep(ev);
}

void Pipeline::addKeyframe(io::LaserScan scan, const std::optional<CameraMeasurement>& camera_motion) {
  const size_t k = map_.size();
  // 1. The previous keyframe's image is final once this keyframe exists (it may be nearer in time).
  if (auto done = images_.keyframeAdded(k, scan.timestamp)) attachImage(*done);
  // 2. Local SLAM: the motion since the previous keyframe, refined by the submap match.
  KeyframeConstraint c = local_.keyframeConstraint(scan, map_);
  if (c.match == KeyframeConstraint::Match::Used) ++stats_.scan_matches_used;
  if (c.match == KeyframeConstraint::Match::Rejected) ++stats_.scan_matches_rejected;
  //    Without scans, the camera's view of the motion refines it instead.
  if (camera_motion && !map_.empty()) {
    const CameraMotionResult r = fuseCameraMotion(c, *camera_motion, 1.0 - options_.local.odometry_outlier_probability);
    c = r.constraint;
    ++(r.used ? stats_.camera_motions_used : stats_.camera_motions_rejected);
  }
  // 3. Global SLAM: the keyframe into the filter as a delayed pose.
  const double timestamp = scan.timestamp;
  const std::array<double, 9> cov = global_.addKeyframe(Keyframe{k, timestamp, {}, std::move(scan), false, {}}, c);
  // 4. The keyframe anchors the trajectory at sensor times and joins the local submap.
  const Keyframe& added = map_.back();
  map_.addAnchor({timestamp, k, common::Pose2{}, local_.motion().odometryPose()});
  local_.keyframeAdded(added.scan);
  for (auto* o : observers_) o->onKeyframe({added.index, added.timestamp, added.pose, cov, &added.scan});
  // 5. Global SLAM: loop closures against earlier keyframes.
  global_.closeLoops(k);
}

}  // namespace urbanslam::slam
