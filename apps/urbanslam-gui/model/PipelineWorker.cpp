#include "PipelineWorker.h"

#include <chrono>

#include "urbanslam/common/Error.h"

namespace urbanslam::gui {

PipelineWorker::PipelineWorker(const std::string& log_path, const std::string& ini_path, const std::string& default_laser_model,
                               const std::string& default_vocabulary)
    : log_path_(log_path), ini_path_(ini_path), default_laser_model_(default_laser_model) {
  slam::PipelineOptions options = slam::loadPipelineOptions(ini_path, &resolved_ini_);
  if (options.loop_closure.laser_model.empty()) options.loop_closure.laser_model = default_laser_model_;
  if (options.image_loop.vocabulary.empty()) options.image_loop.vocabulary = default_vocabulary;
  source_ = io::openDataSource(log_path);
  format_ = source_->format();
  pipeline_ = std::make_unique<slam::Pipeline>(options);
  pipeline_->addObserver(&collector_);
  thread_ = std::thread([this] { loop(); });
}

PipelineWorker::~PipelineWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void PipelineWorker::play() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = true;
  }
  wake_.notify_all();
}

void PipelineWorker::pause() {
  std::lock_guard<std::mutex> lock(mutex_);
  running_ = false;
  step_request_ = false;
}

void PipelineWorker::stepKeyframe() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    step_request_ = true;
    running_ = true;
  }
  wake_.notify_all();
}

void PipelineWorker::setSpeed(double factor) {
  std::lock_guard<std::mutex> lock(mutex_);
  speed_ = factor;
}

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
  if (finished_) return;
  try {
    pipeline_->waitForGlobalSlam(*source_);
  } catch (const std::exception& e) {
    if (error_.empty()) error_ = e.what();
  }
}

void PipelineWorker::loop() {
  using clock = std::chrono::steady_clock;
  clock::time_point wall0 = clock::now();
  double log0 = -1;
  bool was_running = false;
  for (;;) {
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait(lock, [&] { return stop_ || (running_ && !finished_); });
    if (stop_) return;
    if (!was_running) {  // resumed: pace from here
      wall0 = clock::now();
      log0 = -1;
    }
    const size_t keyframes_before = pipeline_->keyframesMade();
    bool more = false;
    try {
      more = pipeline_->step(*source_);
    } catch (const std::exception& e) {
      error_ = e.what();
      more = false;
    }
    if (!more) {
      try {
        pipeline_->finish(*source_);
      } catch (const std::exception& e) {
        if (error_.empty()) error_ = e.what();  // else global SLAM stopped at the same failure
      }
      finished_ = true;
      running_ = false;
      was_running = false;
      continue;
    }
    if (step_request_ && pipeline_->keyframesMade() > keyframes_before) {
      waitForGlobalSlam();  // paused on a keyframe: show it with its closures
      step_request_ = false;
      running_ = false;
    }
    was_running = running_;
    const double speed = speed_;
    const double t = pipeline_->stats().last_timestamp;
    lock.unlock();
    // Real-time pacing: wait until the wall clock catches up with the log's clock, in short
    // naps so pause/stop stay responsive (a log with seconds between measurements, such as a
    // folder of images at 1 s each, must wait the whole gap, not one nap).
    if (speed > 0) {
      if (log0 < 0) log0 = t;
      for (;;) {
        const double ahead = (t - log0) / speed - std::chrono::duration<double>(clock::now() - wall0).count();
        if (ahead <= 0 || stop_ || !running_) break;
        std::this_thread::sleep_for(std::chrono::duration<double>(std::min(ahead, 0.05)));
      }
    }
  }
}

}  // namespace urbanslam::gui
