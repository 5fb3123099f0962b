// The runner behind the GUI's workers: play / step-one-unit interplay, with a job whose steps
// are plain counters (no SLAM), so that every interleaving the test needs is forced by the job.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>

#include "WaitFor.h"
#include "model/PacedRunner.h"

using namespace urbanslam;
using namespace std::chrono_literals;
using test::waitFor;

namespace {
constexpr int kSteps = 50;
}

TEST(PacedRunner, StepUnitRunsOneUnitThenPauses) {
  std::atomic<int> steps{0};
  gui::PacedRunner r([&] {
    gui::PacedRunner::Step s;
    s.more = ++steps < kSteps;
    s.unit_done = steps % 3 == 0;  // a unit is three steps
    return s;
  });
  r.stepUnit();
  ASSERT_TRUE(waitFor([&] { return !r.running(); }, 10s));
  std::this_thread::sleep_for(50ms);  // paused: no further step
  EXPECT_EQ(steps, 3);
  EXPECT_FALSE(r.finished());
  r.stop();
}

// A play that arrives while the single step is running (the GUI's Play pressed right after
// Step) runs the job to its end instead of being undone by the step's end.
TEST(PacedRunner, PlayDuringASingleStepRunsToTheEnd) {
  std::atomic<int> steps{0};
  gui::PacedRunner* runner = nullptr;
  gui::PacedRunner r([&] {
    gui::PacedRunner::Step s;
    if (++steps == 1) runner->play();  // between the unit's work and the runner seeing it done
    s.more = steps < kSteps;
    s.unit_done = true;
    return s;
  });
  runner = &r;
  r.stepUnit();
  ASSERT_TRUE(waitFor([&] { return r.finished(); }, 10s));
  EXPECT_EQ(steps, kSteps);
}
