// Shared-out jobs: each runs exactly once on a worker within the count, whatever the threads do,
// and a job's failure reaches the caller after every thread has stopped.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <algorithm>
#include <stdexcept>
#include <thread>
#include <vector>

#include "urbanslam/common/ParallelJobs.h"

namespace uc = urbanslam::common;

TEST(ParallelJobs, EveryJobRunsOnceOnAWorkerWithinTheCount) {
  for (const size_t workers : {1u, 2u, 3u}) {
    constexpr size_t kJobs = 1000;
    std::vector<std::atomic<int>> runs(kJobs);
    std::vector<std::vector<size_t>> by_worker(workers);  // each worker writes only its own
    uc::runJobs(kJobs, workers, [&](size_t w, size_t job) {
      ASSERT_LT(w, workers);
      ++runs[job];
      by_worker[w].push_back(job);
    });
    size_t total = 0;
    for (size_t j = 0; j < kJobs; ++j) EXPECT_EQ(runs[j].load(), 1) << j;
    for (const auto& jobs : by_worker) {
      total += jobs.size();
      for (size_t k = 1; k < jobs.size(); ++k) EXPECT_LT(jobs[k - 1], jobs[k]);  // a worker takes them in order
    }
    EXPECT_EQ(total, kJobs);
  }
  uc::runJobs(0, 2, [](size_t, size_t) { FAIL() << "no job to run"; });
}

TEST(ParallelJobs, AFailedJobIsRethrownAndTheOthersStop) {
  std::atomic<size_t> ran{0};
  std::atomic<bool> failing{false};
  try {
    uc::runJobs(10000, 2, [&](size_t, size_t job) {
      ++ran;
      if (job == 10) {
        failing = true;
        throw std::runtime_error("job 10 failed");
      }
      // The jobs after it take a while once it fails: a loaded machine can hold the failing
      // thread for milliseconds, in which the other could otherwise run every job left.
      if (job > 10) {
        while (!failing) std::this_thread::yield();
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "job 10 failed");
  }
  EXPECT_LT(ran.load(), 10000u);
}

TEST(ParallelJobs, WorkersAreBoundedByTheJobsAndTheMachine) {
  EXPECT_EQ(uc::workerCount(0, 4), 1u);
  EXPECT_EQ(uc::workerCount(1, 4), 1u);
  EXPECT_EQ(uc::workerCount(100, 1), 1u);
  const size_t machine = std::max(1u, std::thread::hardware_concurrency());
  EXPECT_EQ(uc::workerCount(100, 2), std::min<size_t>(2, machine));
  EXPECT_EQ(uc::workerCount(3, 64), std::min<size_t>(3, machine));
}
