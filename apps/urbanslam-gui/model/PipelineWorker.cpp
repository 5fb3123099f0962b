#include "PipelineWorker.h"

#include "urbanslam/common/Error.h"

namespace urbanslam::gui {

PipelineWorker::PipelineWorker(const std::string& log_path, const std::string& ini_path, const std::string& home)
    : log_path_(log_path), ini_path_(ini_path) {
  slam::PipelineOptions options = slam::loadPipelineOptions(ini_path, &resolved_ini_);
  if (!home.empty()) slam::resolveDefaultPaths(options, home);
  source_ = io::openDataSource(log_path);
  format_ = source_->format();
  pipeline_ = std::make_unique<slam::Pipeline>(options);
  pipeline_->addObserver(&collector_);
}

PipelineWorker::~PipelineWorker() { runner_.stop(); }

std::string PipelineWorker::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

void PipelineWorker::withPipeline(const std::function<void(const slam::Pipeline&)>& f) {
  std::lock_guard<std::mutex> lock(mutex_);
  waitForGlobalSlam();
  f(*pipeline_);
}

void PipelineWorker::waitForGlobalSlam() {
  if (done_) return;
  try {
    pipeline_->waitForGlobalSlam(*source_);
  } catch (const std::exception& e) {
    if (error_.empty()) error_ = e.what();
  }
}

PacedRunner::Step PipelineWorker::step() {
  std::lock_guard<std::mutex> lock(mutex_);
  PacedRunner::Step s;
  if (done_) {
    s.more = false;
    return s;
  }
  const size_t keyframes_before = pipeline_->keyframesMade();
  try {
    s.more = pipeline_->step(*source_);
  } catch (const std::exception& e) {
    error_ = e.what();
    s.more = false;
  }
  if (!s.more) {
    try {
      pipeline_->finish(*source_);
    } catch (const std::exception& e) {
      if (error_.empty()) error_ = e.what();  // else global SLAM stopped at the same failure
    }
    done_ = true;
    return s;
  }
  if (pipeline_->keyframesMade() > keyframes_before && runner_.unitRequested()) {
    waitForGlobalSlam();  // paused on a keyframe: show it with its closures
    s.unit_done = true;
  }
  s.paced = true;
  s.log_time = pipeline_->stats().last_timestamp;
  return s;
}

}  // namespace urbanslam::gui
