#pragma once
// Runs jobs one after the other, in the order they were posted, either on a thread of its own
// (the poster goes on at once) or inline in post() (the same order, no thread). Used where one
// stage must never wait for a slower one that works on its own state: global SLAM behind local
// SLAM. A job that throws stops the worker; the exception is rethrown to the poster by the next
// post(), drain() or rethrowIfFailed(), and the jobs after it are dropped.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace urbanslam::common {

class SerialWorker {
 public:
  explicit SerialWorker(bool threaded);
  // Drops the jobs not started yet and waits for the running one.
  ~SerialWorker();
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  bool threaded() const { return threaded_; }
  // Returns the job's ticket, for waitFor().
  size_t post(std::function<void()> job);
  // Waits until every posted job has run.
  void drain();
  // Waits until the job with this ticket (and so every job before it) has run.
  void waitFor(size_t ticket);
  void rethrowIfFailed();
  // Jobs posted and not finished yet, and the most there ever were.
  size_t backlog() const;
  size_t maxBacklog() const;

 private:
  void loop();

  const bool threaded_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;  // a job or the stop for the thread
  std::condition_variable idle_;  // a job finished, for drain() and waitFor()
  std::deque<std::function<void()>> jobs_;
  size_t running_ = 0;
  size_t posted_ = 0, done_ = 0;  // jobs posted and run: a job's ticket is posted_ after its post
  size_t max_backlog_ = 0;
  bool stop_ = false;
  std::exception_ptr failure_;
  std::thread thread_;
};

}  // namespace urbanslam::common
