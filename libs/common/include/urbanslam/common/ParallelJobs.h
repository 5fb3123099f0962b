#pragma once
// Independent jobs 0..n-1 shared out to a few threads (the calling one among them), each taking
// the next job as it finishes one: the output phase's per-block and per-keyframe work, which
// only reads the map. The first exception a job throws is rethrown once every thread has
// stopped (the others stop after their current job).
#include <cstddef>
#include <functional>

namespace urbanslam::common {

// Threads for `jobs` jobs: at most max_workers and the machine's hardware threads, at least one.
size_t workerCount(size_t jobs, size_t max_workers);

// work(worker, job) for every job, worker < workers: what a worker keeps between its jobs
// (scratch buffers, a grid) is indexed by it.
void runJobs(size_t jobs, size_t workers, const std::function<void(size_t worker, size_t job)>& work);

}  // namespace urbanslam::common
