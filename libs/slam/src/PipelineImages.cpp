// The pipeline's camera side: images attached to keyframes, Tree of Words proposals turned into
// loop-closure hypotheses (thesis §4.2 detection, then the same §5.3 alignment and §5.4 gating
// as the laser candidates).
#include <opencv2/core.hpp>

#include "urbanslam/common/Timing.h"
#include "urbanslam/esdf/Esdf.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/vision_loop/LoopDetector.h"
#include "urbanslam/vision_loop/VocabularyFile.h"

namespace urbanslam::slam {

void Pipeline::startImageDetector() {
  if (image_detector_ || options_.loop_closure.image_detector != "tree_of_words") return;
  // Tree of Words over the keyframe images (thesis §4.2); the vocabulary decides SIFT or ORB.
  // Loaded at the first image, so a log without a camera never reads it.
  const std::string path = options_.image_loop.vocabulary.empty() ? vision_loop::kDefaultVocabularyPath : options_.image_loop.vocabulary;
  auto vocabulary = std::make_shared<const vision_loop::Vocabulary>(vision_loop::loadVocabulary(path));
  const auto features = vision_loop::featureOptions(options_.image_loop, vocabulary->descriptorType());
  image_detector_ = std::make_unique<vision_loop::LoopDetector>(vocabulary, features, vision_loop::detectorOptions(options_.image_loop));
}

void Pipeline::onCameraImage(const io::CameraImage& image, double progress) {
  if (!image.pixels || image.width <= 0 || image.height <= 0) return;
  startImageDetector();
  if (stats_.scans > 0) {
    images_.addImage(image);  // goes to the nearest keyframe in time, decided one keyframe later
    return;
  }
  // No laser so far (a camera-only log): every image is a keyframe, without motion if there is
  // no odometry, so loop proposals can still be found and reported.
  common::Stopwatch sw;
  io::LaserScan none;
  none.timestamp = image.timestamp;
  none.label = image.label;
  addKeyframe(std::move(none));
  attachImage(images_.imageKeyframe(keyframes_.size() - 1, image));
  const double ms = sw.milliseconds();
  stats_.keyframe_ms.push_back(ms);
  stats_.recordStep(ms, keyframes_.size());
  StepEvent ev{stats_.scans_used, keyframes_.size(), stats_.last_timestamp, ms, progress};
  for (auto* o : observers_) o->onStep(ev);
}

void Pipeline::attachImage(const AssignedImage& assigned) {
  Keyframe& kf = keyframes_[assigned.keyframe];
  kf.has_image = true;
  ++stats_.image_keyframes;
  for (auto* o : observers_) o->onKeyframeImage({assigned.keyframe, &assigned.image});
  if (!image_detector_) return;
  // Words once per keyframe: kept on the keyframe (the pixels are not), then queried against
  // and added to the database.
  const io::CameraImage& im = assigned.image;
  const cv::Mat gray(im.height, im.width, CV_8U, const_cast<uint8_t*>(im.pixels->data()));
  vision_loop::ImageFeatures features = image_detector_->extractor().extract(gray);
  vision_loop::BagOfWords bag = image_detector_->vocabulary().transform(features.descriptors);
  kf.image_words = bag;
  const vision_loop::LoopResult r = image_detector_->process(std::move(features), std::move(bag));
  image_keyframes_.push_back(assigned.keyframe);
  if (r.detected()) proposeImageClosure(image_keyframes_[r.match], assigned.keyframe, r.normalized_score);
}

void Pipeline::proposeImageClosure(size_t earlier, size_t current, double score) {
  ++stats_.image_proposals;
  ImageMatchEvent ev{current, earlier, score, false, ""};
  const bool filter = options_.estimator.type == "esdf";
  if (filter && options_.loop_closure.enabled && keyframes_[earlier].hasScan() && keyframes_[current].hasScan()) {
    // The same path as a laser candidate: alignment, gating, confirmation by a second closure.
    common::Stopwatch sw;
    expirePending(current);
    const bool confirm = options_.loop_closure.confirm_window > 0;
    const Detection detection{"image", score};
    LoopClosureRecord r = closer_.tryClose(*esdf_, keyframes_, earlier, current, !confirm, &detection);
    ++stats_.closures_tried;
    const std::string reason = r.reason;
    const Admission a = admit(std::move(r), current);
    ev.accepted = a == Admission::Accepted;
    ev.fate = a == Admission::Accepted ? "accepted" : a == Admission::Pending ? "pending" : (reason.empty() ? "gating" : reason);
    if (ev.accepted) recoverAll();
    stats_.closure_ms.push_back(sw.milliseconds());
  } else {
    // Without scans (or a filter) the pair cannot be aligned: a proposal on record, never a
    // constraint.
    LoopClosureRecord r;
    r.from = earlier;
    r.to = current;
    r.from_time = keyframes_[earlier].timestamp;
    r.to_time = keyframes_[current].timestamp;
    r.detector = "image";
    r.score = score;
    r.reason = !filter ? "no_filter" : !options_.loop_closure.enabled ? "loop_closure_disabled" : "no_scans";
    ev.fate = r.reason;
    reportClosure(r);
  }
  for (auto* o : observers_) o->onImageMatch(ev);
}

}  // namespace urbanslam::slam
