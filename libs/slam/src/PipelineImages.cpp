// The pipeline's camera side: images attached to keyframes, Tree of Words proposals turned into
// loop-closure hypotheses (thesis §4.2 detection, then the same §5.3 alignment and §5.4 gating
// as the laser candidates).
#include <algorithm>
#include <iterator>
#include <opencv2/core.hpp>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/slam/KeyframeNodes.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/vision_loop/LoopDetector.h"
#include "urbanslam/vision_loop/PlanarRelativePose.h"
#include "urbanslam/vision_loop/VocabularyFile.h"

namespace urbanslam::slam {

namespace {
// An image confirms closures of keyframes at most this many from its own: a camera at 2 Hz beside
// a laser at 10 Hz has an image every five keyframes at driving speed, so one within two or three
// of any keyframe.
constexpr size_t kImageReachKeyframes = 3;
}  // namespace

void Pipeline::startImageDetector() {
  if (image_detector_ || options_.loop_closure.image_detector != LoopClosureOptions::ImageDetector::TreeOfWords) return;
  // Tree of Words over the keyframe images (thesis §4.2); the vocabulary decides SIFT or ORB.
  // Loaded at the first image, so a log without a camera never reads it.
  const std::string path = options_.image_loop.vocabulary.empty() ? vision_loop::kDefaultVocabularyPath : options_.image_loop.vocabulary;
  auto vocabulary = std::make_shared<const vision_loop::Vocabulary>(vision_loop::loadVocabulary(path));
  const auto features = vision_loop::featureOptions(options_.image_loop, vocabulary->descriptorType());
  image_detector_ = std::make_unique<vision_loop::LoopDetector>(vocabulary, features, vision_loop::detectorOptions(options_.image_loop));
  global_.setCameraMeasurer([this](size_t earlier, size_t current) { return cameraView(earlier, current); });
}

std::optional<size_t> Pipeline::nearestImage(size_t keyframe) const {
  // image_keyframes_ grows with the keyframes: sorted. The nearest is the first at or after the
  // keyframe or the one before it (the earlier on a tie).
  const auto after = std::lower_bound(image_keyframes_.begin(), image_keyframes_.end(), keyframe);
  std::optional<size_t> best;
  size_t best_gap = kImageReachKeyframes + 1;
  const auto consider = [&](std::vector<size_t>::const_iterator c) {
    const size_t gap = *c > keyframe ? *c - keyframe : keyframe - *c;
    if (gap < best_gap) best_gap = gap, best = static_cast<size_t>(c - image_keyframes_.begin());
  };
  if (after != image_keyframes_.begin()) consider(std::prev(after));
  if (after != image_keyframes_.end()) consider(after);
  return best;
}

std::optional<CameraPairView> Pipeline::cameraView(size_t earlier, size_t current) {
  const std::optional<size_t> a = nearestImage(earlier), b = nearestImage(current);
  if (!a || !b || *a >= *b) return std::nullopt;
  const size_t ka = image_keyframes_[*a], kb = image_keyframes_[*b];
  // The full pose only where the estimate tells a facade from its copy (as for the camera's own
  // closures): farther, a confirmation by the camera could be a copy's.
  if (!options_.image_loop.metric_pose || !global_.allowsFullCameraPose(ka, kb)) return std::nullopt;
  const auto pair = std::make_pair(*a, *b);
  for (const auto& [key, view] : camera_views_)
    if (key == pair) return view;
  const auto id = [](size_t i) { return static_cast<vision_loop::ImageId>(i); };
  std::optional<CameraPairView> view;
  std::optional<CameraMeasurement> m =
      measureCamera(image_cameras_[*a], image_detector_->features(id(*a)), image_cameras_[*b], image_detector_->features(id(*b)));
  if (m && m->relative.valid) {
    measureLength(*a, *b, *m);
    if (m->metric.valid) view = CameraPairView{ka, kb, *m};
  }
  camera_views_.emplace_back(pair, view);
  return view;
}

void Pipeline::onCameraImage(const io::CameraImage& image, double progress) {
  if (!image.pixels || image.width <= 0 || image.height <= 0) return;
  startImageDetector();
  if (stats_.scans > 0) {
    images_.addImage(image);  // goes to the nearest keyframe in time, decided one keyframe later
    return;
  }
  // No laser so far (a camera-only log): every image is a keyframe, without motion if there is
  // no odometry, so loop proposals can still be found and reported. With a calibrated camera,
  // its view of the motion since the previous keyframe's image refines the odometry.
  common::Stopwatch sw;
  std::optional<PreparedImage> prepared;
  std::optional<CameraMeasurement> camera_motion;
  if (image_detector_) {
    prepared = prepareImage(image);
    // The previous image's features are in the image database, which global SLAM fills: this
    // keyframe waits for it (camera-only logs run in step with global SLAM).
    global_worker_.drain();
    const size_t previous = image_keyframes_.size();
    if (previous > 0 && image_keyframes_.back() + 1 == local_.keyframes())
      camera_motion =
          measureCamera(image_cameras_[previous - 1], image_detector_->features(static_cast<vision_loop::ImageId>(previous - 1)),
                        {image.calibration, image.width}, prepared->features);
  }
  io::LaserScan none;
  none.timestamp = image.timestamp;
  none.label = image.label;
  addKeyframe(std::move(none), camera_motion);
  postImage(images_.imageKeyframe(local_.keyframes() - 1, image), std::move(prepared));
  const double ms = sw.milliseconds();
  stats_.keyframe_ms.add(ms);
  stats_.recordStep(ms, local_.keyframes());
  StepEvent ev{stats_.scans_used, local_.keyframes(), stats_.last_timestamp, ms, progress};
  for (auto* o : observers_) o->onStep(ev);
}

Pipeline::PreparedImage Pipeline::prepareImage(const io::CameraImage& im) const {
  const cv::Mat gray(im.height, im.width, CV_8U, const_cast<uint8_t*>(im.pixels->data()));
  PreparedImage p;
  p.features = image_detector_->extractor().extract(gray);
  p.words = image_detector_->vocabulary().transform(p.features.descriptors);
  return p;
}

void Pipeline::postImage(AssignedImage assigned, std::optional<PreparedImage> prepared) {
  postToGlobalSlam([this, assigned = std::move(assigned), prepared = std::move(prepared),
                    handed_over = std::chrono::steady_clock::now()]() mutable { attachImage(assigned, std::move(prepared), handed_over); });
}

void Pipeline::attachImage(const AssignedImage& assigned, std::optional<PreparedImage> prepared, SteadyTime handed_over) {
  Keyframe& kf = map_.keyframe(assigned.keyframe);
  kf.has_image = true;
  ++stats_.image_keyframes;
  for (auto* o : observers_) o->onKeyframeImage({assigned.keyframe, &assigned.image});
  if (!image_detector_) return;
  // Words once per keyframe: kept on the keyframe (the pixels are not), then queried against
  // and added to the database.
  const io::CameraImage& im = assigned.image;
  if (!prepared) prepared = prepareImage(im);
  kf.image_words = prepared->words;
  const vision_loop::LoopResult r = image_detector_->process(std::move(prepared->features), std::move(prepared->words));
  image_keyframes_.push_back(assigned.keyframe);
  image_cameras_.push_back({im.calibration, im.width});
  if (!r.detected()) return;
  const auto id = [](size_t i) { return static_cast<vision_loop::ImageId>(i); };
  std::optional<CameraMeasurement> camera = measureCamera(image_cameras_[r.match], image_detector_->features(id(r.match)),
                                                          image_cameras_[r.query], image_detector_->features(id(r.query)));
  // The full pose is measured only where global SLAM would use it (a tenth of the proposals of a
  // camera run: most come after drift), as it costs two more feature matchings and a PnP.
  if (camera && camera->relative.valid && global_.allowsFullCameraPose(image_keyframes_[r.match], assigned.keyframe))
    measureLength(r.match, r.query, *camera);
  global_.proposeImageClosure(image_keyframes_[r.match], assigned.keyframe, r.normalized_score, camera, handed_over);
}

void Pipeline::measureLength(size_t earlier_image, size_t current_image, CameraMeasurement& m) {
  KeyframeNodes* filter = map_.nodes();
  if (!options_.image_loop.metric_pose || !filter) return;
  // The earlier keyframe's neighbour in the same visit: the next image, else the previous, of a
  // keyframe at most twice kImageReachKeyframes away (with a laser, the images fall between its
  // keyframes; without, every image is a keyframe), taken by the same camera.
  const size_t a = image_keyframes_[earlier_image];
  const size_t reach = 2 * kImageReachKeyframes;
  const auto usable = [&](size_t n) {
    return n < image_keyframes_.size() && n != current_image && image_cameras_[n].width == image_cameras_[earlier_image].width &&
           image_cameras_[n].calibration == image_cameras_[earlier_image].calibration &&
           (image_keyframes_[n] > a ? image_keyframes_[n] - a : a - image_keyframes_[n]) <= reach;
  };
  const size_t n = usable(earlier_image + 1)                        ? earlier_image + 1
                   : earlier_image > 0 && usable(earlier_image - 1) ? earlier_image - 1
                                                                    : current_image;
  if (n == current_image) return;
  // The baseline from the estimate of the two keyframes, its uncertainty along the baseline from
  // their relative covariance (the odometry between them, mostly).
  const auto& kf = map_.keyframes();
  const common::Pose2 ca = common::compose(kf[a].pose, m.mount), cn = common::compose(kf[image_keyframes_[n]].pose, m.mount);
  const double baseline = std::hypot(cn.x - ca.x, cn.y - ca.y);
  if (!(baseline > 0)) return;
  const common::Pose2 rel = common::between(kf[a].pose, kf[image_keyframes_[n]].pose);
  const Eigen::Matrix3d cov =
      filter->relativeCovariance(a, image_keyframes_[n], esdf::CovarianceMode::Conservative);
  const double len = std::max(1e-9, std::hypot(rel.x, rel.y));
  const Eigen::Vector2d dir(rel.x / len, rel.y / len);
  const double sigma = std::sqrt(std::max(0.0, dir.dot(cov.topLeftCorner<2, 2>() * dir)));
  const auto& o = options_.image_loop;
  vision_loop::MetricRelativePoseOptions mo;
  mo.ratio = o.ratio;
  mo.floor_forward_m = o.metric_floor_forward_m;
  mo.floor_left_m = o.metric_floor_left_m;
  mo.floor_heading_rad = o.metric_floor_heading_deg * M_PI / 180;
  const auto id = [](size_t i) { return static_cast<vision_loop::ImageId>(i); };
  const auto& fa = image_detector_->features(id(earlier_image));
  const auto type = image_detector_->vocabulary().descriptorType();
  const vision_loop::PinholeCamera k =
      pinholeFor(*image_cameras_[earlier_image].calibration, image_cameras_[earlier_image].width, fa.image_size.width);
  const vision_loop::StereoPoints stereo =
      vision_loop::triangulateWithSecondImage(fa, image_detector_->features(id(n)), type, k, baseline, sigma, mo);
  m.metric = vision_loop::metricRelativePose(stereo, fa, image_detector_->features(id(current_image)), type, k, mo);
}

std::optional<CameraMeasurement> Pipeline::measureCamera(const ImageCamera& a, const vision_loop::ImageFeatures& fa, const ImageCamera& b,
                                                         const vision_loop::ImageFeatures& fb) const {
  if (!a.calibration || !b.calibration) return std::nullopt;
  // One camera seen twice: the relative pose of two different cameras is not this measurement.
  const auto& cb = *b.calibration;
  if (a.width != b.width || !(*a.calibration == cb)) return std::nullopt;
  CameraMeasurement m;
  m.mount = cb.mount;
  m.relative =
      vision_loop::planarRelativePose(fa, fb, image_detector_->vocabulary().descriptorType(), pinholeFor(cb, b.width, fb.image_size.width));
  return m;
}

}  // namespace urbanslam::slam
