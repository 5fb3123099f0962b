#pragma once
// Wall-clock timing of pipeline stages, and the percentiles quoted in stats.json and benches.
#include <chrono>
#include <vector>

namespace urbanslam::common {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void restart() { start_ = std::chrono::steady_clock::now(); }
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  double milliseconds() const { return 1e3 * seconds(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Percentile p in [0,100] by linear interpolation between order statistics (NumPy's default).
// Returns 0 for an empty sample. Takes a copy: callers keep their sample order.
double percentile(std::vector<double> sample, double p);

// CPU time used so far by the whole process (every thread) and by the calling thread, in seconds:
// what a run costs on one core, apart from the other jobs that share the machine's wall time.
double processCpuSeconds();
double threadCpuSeconds();

// Peak resident memory of this process in bytes (0 where unknown).
long long peakResidentBytes();

}  // namespace urbanslam::common
