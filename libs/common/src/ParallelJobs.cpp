#include "urbanslam/common/ParallelJobs.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace urbanslam::common {

size_t workerCount(size_t jobs, size_t max_workers) {
  return std::max<size_t>(1, std::min<size_t>({jobs, max_workers, std::max(1u, std::thread::hardware_concurrency())}));
}

void runJobs(size_t jobs, size_t workers, const std::function<void(size_t worker, size_t job)>& work) {
  workers = std::max<size_t>(1, workers);
  std::atomic<size_t> next{0};
  std::vector<std::exception_ptr> failed(workers);
  const auto run = [&](size_t w) {
    try {
      for (size_t job = next++; job < jobs; job = next++) work(w, job);
    } catch (...) {
      failed[w] = std::current_exception();
      next = jobs;  // the others stop after their current job
    }
  };
  std::vector<std::thread> threads;
  for (size_t w = 1; w < workers; ++w) threads.emplace_back(run, w);
  run(0);
  for (auto& t : threads) t.join();
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace urbanslam::common
