// The serial worker runs jobs in the order they were posted, on its thread or inline, waits
// for them on drain(), and hands a job's exception back to the poster.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "urbanslam/common/SerialWorker.h"

using urbanslam::common::SerialWorker;

class SerialWorkerTest : public ::testing::TestWithParam<bool> {};

TEST_P(SerialWorkerTest, RunsJobsInPostingOrderAndDrainWaitsForAll) {
  SerialWorker w(GetParam());
  std::vector<int> order;  // written by the worker only, read after drain()
  const std::thread::id poster = std::this_thread::get_id();
  std::atomic<int> on_poster{0};
  for (int i = 0; i < 200; ++i)
    w.post([&, i] {
      if (i % 7 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));  // some jobs slower than posting
      if (std::this_thread::get_id() == poster) ++on_poster;
      order.push_back(i);
    });
  w.drain();
  ASSERT_EQ(order.size(), 200u);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(order[static_cast<size_t>(i)], i);
  EXPECT_EQ(on_poster.load(), GetParam() ? 0 : 200);
  EXPECT_EQ(w.backlog(), 0u);
  if (GetParam())
    EXPECT_GE(w.maxBacklog(), 1u);
  else
    EXPECT_EQ(w.maxBacklog(), 0u);  // inline: nothing ever waits
}

TEST_P(SerialWorkerTest, AFailedJobStopsTheWorkerAndReachesThePoster) {
  SerialWorker w(GetParam());
  std::atomic<int> ran{0};
  w.post([&] { ++ran; });
  try {
    w.post([] { throw std::runtime_error("job 2 failed"); });
  } catch (const std::runtime_error&) {  // inline: at once
  }
  try {
    w.post([&] { ++ran; });
  } catch (const std::runtime_error&) {
  }
  try {
    w.drain();
    FAIL() << "drain() after a failed job returned";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "job 2 failed");
  }
  EXPECT_EQ(ran.load(), 1);  // the job after the failure never ran
  EXPECT_THROW(w.post([&] { ++ran; }), std::runtime_error);
  EXPECT_THROW(w.rethrowIfFailed(), std::runtime_error);
  EXPECT_EQ(ran.load(), 1);
}

TEST(SerialWorker, ThreadedPosterDoesNotWaitForASlowJob) {
  SerialWorker w(true);
  std::atomic<bool> release{false};
  std::atomic<bool> done{false};
  w.post([&] {
    while (!release) std::this_thread::yield();
    done = true;
  });
  w.post([] {});
  EXPECT_FALSE(done.load());  // post() returned while the first job still runs
  EXPECT_EQ(w.backlog(), 2u);
  release = true;
  w.drain();
  EXPECT_TRUE(done.load());
}

TEST(SerialWorker, DestructionDropsWaitingJobs) {
  std::atomic<int> ran{0};
  std::atomic<bool> started{false}, release{false};
  std::thread releaser;
  {
    SerialWorker w(true);
    w.post([&] {
      started = true;
      while (!release) std::this_thread::yield();
      ++ran;
    });
    for (int i = 0; i < 10; ++i) w.post([&] { ++ran; });
    while (!started) std::this_thread::yield();
    releaser = std::thread([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      release = true;
    });
  }  // waits for the running job only
  releaser.join();
  EXPECT_EQ(ran.load(), 1);
}

INSTANTIATE_TEST_SUITE_P(Threads, SerialWorkerTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Threaded" : "Inline"; });

TEST(SerialWorker, WaitForReturnsOnceThatJobHasRunNotTheLaterOnes) {
  SerialWorker w(true);
  std::atomic<bool> release{false};
  std::atomic<int> ran{0};
  const size_t first = w.post([&] { ++ran; });
  const size_t second = w.post([&] {
    while (!release) std::this_thread::yield();
    ++ran;
  });
  EXPECT_EQ(second, first + 1);
  w.waitFor(first);
  EXPECT_GE(ran.load(), 1);
  EXPECT_EQ(w.backlog(), 1u);  // the second still runs: waitFor did not wait for it
  release = true;
  w.waitFor(second);
  EXPECT_EQ(ran.load(), 2);
}

TEST_P(SerialWorkerTest, WaitingForAJobAfterAFailedOneRethrowsInsteadOfHanging) {
  SerialWorker w(GetParam());
  try {
    w.post([] { throw std::runtime_error("job 1 failed"); });
  } catch (const std::runtime_error&) {  // inline: at once
  }
  size_t later = 2;
  try {
    later = w.post([] {});
  } catch (const std::runtime_error&) {
  }
  EXPECT_THROW(w.waitFor(later), std::runtime_error);
}
