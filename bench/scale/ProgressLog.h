#pragma once
// A long run's figures as it goes: one CSV row every `every` keyframes (and at 10², 10³), flushed
// at once, so that a run stopped before its end still says how its cost and memory grew.
//
// Columns: keyframes; log_s (log time since the first measurement); wall_s; cpu_s (the whole
// process: what one core would need); front_cpu_s (the thread that reads the sensors and runs
// local SLAM, the simulator's ray casting included when the city is streamed); rss_mb (now) and
// peak_rss_mb; heap_mb (the bytes malloc has handed out and not had back, over all its arenas:
// what the run's data takes, against which rss_mb shows the allocator's free but kept pages); closures (accepted), attempts (candidates
// aligned or refused, all proposers) and laser_attempts (those the laser classifier proposed: far from the map each costs CRF-match and
// ICP); full_recoveries and full_recovery_s (global SLAM's passes over the whole map, the part of its work that grows with the map) and
// factorisations (of the whole map, by the recoveries and the innovation gate's exact covariances, as of the last recovery) and filter_poses
// (the filter's poses at the last recovery: fewer than the keyframes where they hang from others').
//
// A run continued from a checkpoint (slam/Checkpoint.h) appends to the same file: the rows written
// after the checkpoint are dropped, and the times and counts go on from the checkpoint's (its CPU
// and wall time, and the counters totals() saved with it). The time spent loading the checkpoint
// is not counted; peak_rss_mb is then the peak since the continuation.
#include <malloc.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "urbanslam/common/Timing.h"
#include "urbanslam/slam/Checkpoint.h"
#include "urbanslam/slam/Observer.h"

namespace urbanslam::bench {

using common::processCpuSeconds;
using common::threadCpuSeconds;

inline double residentMegabytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

inline double heapInUseMegabytes() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
}

// Keeps the header line and the first `rows` rows of a CSV file (a continued run's, whose later
// rows came after its checkpoint); `header` is written when the file is missing.
inline void keepCsvRows(const std::string& path, size_t rows, const std::string& header) {
  std::ifstream in(path);
  std::ostringstream kept;
  std::string line;
  if (!std::getline(in, line)) line = header;
  kept << line << "\n";
  for (size_t i = 0; i < rows && std::getline(in, line); ++i) kept << line << "\n";
  in.close();
  std::ofstream(path, std::ios::trunc) << kept.str();
}

class ProgressLog : public slam::PipelineObserver {
 public:
  static constexpr const char* kHeader =
      "keyframes,log_s,wall_s,cpu_s,front_cpu_s,rss_mb,peak_rss_mb,heap_mb,closures,attempts,laser_attempts,full_recoveries,full_"
      "recovery_s,factorisations,filter_poses";
  // `earlier`: the checkpoint the run continues, its counters this log's totals() (a default
  // one for a run from its start).
  explicit ProgressLog(const std::string& path, size_t every, const slam::CheckpointInfo& earlier = {}) : every_(every) {
    const auto get = [&](const char* key) {
      const auto it = earlier.counters.find(key);
      return it == earlier.counters.end() ? 0.0 : it->second;
    };
    keepCsvRows(path, static_cast<size_t>(get("progress_rows")), kHeader);
    csv_.open(path, std::ios::app);
    rows_ = static_cast<size_t>(get("progress_rows"));
    wall0_ = earlier.wall_s, cpu0_ = earlier.cpu_s - processCpuSeconds(), front0_ = get("front_cpu_s") - threadCpuSeconds();
    if (earlier.counters.count("first_timestamp")) first_timestamp_ = get("first_timestamp");
    closures_ = static_cast<size_t>(get("closures")), attempts_ = static_cast<size_t>(get("attempts"));
    laser_attempts_ = static_cast<size_t>(get("laser_attempts")), recoveries_ = static_cast<size_t>(get("full_recoveries"));
    recovery_us_ = static_cast<long long>(get("full_recovery_s") * 1e6);
    factorisations_ = static_cast<long long>(get("factorisations")), filter_poses_ = static_cast<int>(get("filter_poses"));
  }
  // What a continued run goes on from besides the checkpoint's own CPU and wall time; read while
  // global SLAM is idle.
  std::map<std::string, double> totals() const {
    return {{"progress_rows", static_cast<double>(rows_)},
            {"first_timestamp", first_timestamp_},
            {"front_cpu_s", front0_ + threadCpuSeconds()},
            {"closures", static_cast<double>(closures_.load())},
            {"attempts", static_cast<double>(attempts_.load())},
            {"laser_attempts", static_cast<double>(laser_attempts_.load())},
            {"full_recoveries", static_cast<double>(recoveries_.load())},
            {"full_recovery_s", static_cast<double>(recovery_us_.load()) / 1e6},
            {"factorisations", static_cast<double>(factorisations_.load())},
            {"filter_poses", static_cast<double>(filter_poses_.load())}};
  }
  // From the thread that reads the sensors.
  void onStep(const slam::StepEvent& e) override {
    if (first_timestamp_ < 0) first_timestamp_ = e.timestamp;
    last_log_s_ = e.timestamp - first_timestamp_;
    if (e.keyframes == last_row_ || !due(e.keyframes)) return;
    last_row_ = e.keyframes;
    ++rows_;
    char row[256];
    std::snprintf(row, sizeof row, "%zu,%.1f,%.1f,%.1f,%.1f,%.0f,%.0f,%.0f,%zu,%zu,%zu,%zu,%.1f,%lld,%d\n", e.keyframes,
                  last_log_s_, wall0_ + wall_.seconds(), cpu0_ + processCpuSeconds(), front0_ + threadCpuSeconds(), residentMegabytes(),
                  static_cast<double>(common::peakResidentBytes()) / (1024.0 * 1024.0), heapInUseMegabytes(), closures_.load(),
                  attempts_.load(), laser_attempts_.load(), recoveries_.load(), static_cast<double>(recovery_us_.load()) / 1e6,
                  factorisations_.load(), filter_poses_.load());
    csv_ << row << std::flush;
  }
  // From global SLAM, which may run on its own thread.
  void onLoopClosure(const slam::LoopClosureEvent& e) override {
    ++attempts_;
    if (e.detector == slam::Proposer::Laser) ++laser_attempts_;
    if (e.accepted) ++closures_;
  }
  void onPosesUpdated(const slam::PosesUpdatedEvent& e) override {
    ++recoveries_;
    recovery_us_ += static_cast<long long>(e.recovery_ms * 1e3);
    factorisations_ = e.map_factorisations;
    filter_poses_ = e.filter_poses;
  }

 private:
  bool due(size_t keyframes) const { return keyframes == 100 || keyframes == 1000 || (keyframes > 0 && keyframes % every_ == 0); }
  std::ofstream csv_;
  size_t every_;
  size_t last_row_ = 0, rows_ = 0;
  double first_timestamp_ = -1, last_log_s_ = 0, wall0_ = 0, cpu0_ = 0, front0_ = 0;
  common::Stopwatch wall_;
  std::atomic<size_t> closures_{0}, attempts_{0}, laser_attempts_{0}, recoveries_{0};
  std::atomic<long long> recovery_us_{0};
  std::atomic<long long> factorisations_{0};
  std::atomic<int> filter_poses_{0};
};

}  // namespace urbanslam::bench
