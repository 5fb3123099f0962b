#include "urbanslam/common/SerialWorker.h"

#include <algorithm>

namespace urbanslam::common {

SerialWorker::SerialWorker(bool threaded) : threaded_(threaded) {
  if (threaded_) thread_ = std::thread([this] { loop(); });
}

SerialWorker::~SerialWorker() {
  if (!threaded_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    jobs_.clear();
  }
  wake_.notify_all();
  thread_.join();
}

size_t SerialWorker::post(std::function<void()> job) {
  if (!threaded_) {
    rethrowIfFailed();
    ++posted_;
    try {
      job();
    } catch (...) {
      failure_ = std::current_exception();
      throw;
    }
    ++done_;
    return posted_;
  }
  size_t ticket = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (failure_) std::rethrow_exception(failure_);
    jobs_.push_back(std::move(job));
    ticket = ++posted_;
    max_backlog_ = std::max(max_backlog_, jobs_.size() + running_);
  }
  wake_.notify_one();
  return ticket;
}

void SerialWorker::waitFor(size_t ticket) {
  if (threaded_) {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [&] { return done_ >= ticket || failure_; });
  }
  rethrowIfFailed();
}

void SerialWorker::drain() {
  if (threaded_) {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [&] { return (jobs_.empty() && running_ == 0) || failure_; });
  }
  rethrowIfFailed();
}

void SerialWorker::rethrowIfFailed() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (failure_) std::rethrow_exception(failure_);
}

size_t SerialWorker::backlog() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return jobs_.size() + running_;
}

size_t SerialWorker::maxBacklog() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return max_backlog_;
}

void SerialWorker::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || !jobs_.empty(); });
    if (stop_) return;
    std::function<void()> job = std::move(jobs_.front());
    jobs_.pop_front();
    running_ = 1;
    lock.unlock();
    std::exception_ptr failed;
    try {
      job();
    } catch (...) {
      failed = std::current_exception();
    }
    lock.lock();
    running_ = 0;
    ++done_;
    if (failed) {
      failure_ = failed;
      jobs_.clear();
    }
    idle_.notify_all();
  }
}

}  // namespace urbanslam::common
