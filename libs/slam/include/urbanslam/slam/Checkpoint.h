#pragma once
// A long run saved as it goes, so that an interruption (a crash, a killed job, a machine that
// goes down) loses at most the work since the last checkpoint. A checkpoint is a folder beside
// the run's output (OUT.checkpoint/, replaced as a whole: common::AtomicFolder) holding the map
// (map.usmap, MapFile.h) and checkpoint.ini: which input was being read, how many of its
// measurements the map has taken, and the run's CPU and wall time so far. Continuing loads the
// map and reads past the measurements already taken, so the run ends as one that was never
// interrupted: the same keyframes, closures and poses (`CheckpointTest`).
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "urbanslam/common/Timing.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/slam/Pipeline.h"

namespace urbanslam::slam {

struct CheckpointInfo {
  std::string input;                       // the log (or simulated city's ini) the run reads
  std::uint64_t input_measurements = 0;    // of that input, taken by the map (what a continued run skips)
  std::uint64_t keyframes = 0;             // the map's keyframes then (checked against the map)
  double cpu_s = 0;                        // the run's CPU time (all threads) and wall time up to the checkpoint,
  double wall_s = 0;                       // over every earlier stretch of it
  std::string resumed_map;                 // the map file the run continued (run --resume), "" for none
  std::map<std::string, double> counters;  // a caller's running totals (a benchmark's), carried over
};

// Where a run writing `out` keeps its checkpoint.
std::string checkpointPath(const std::string& out);

// Saves a pipeline mid-run (before finish(); it waits for global SLAM first) with its info,
// replacing the checkpoint at `dir` as a whole. Throws common::InputError when it cannot write.
void saveCheckpoint(const Pipeline& pipeline, const std::string& dir, const CheckpointInfo& info);

struct Checkpoint {
  std::unique_ptr<Pipeline> pipeline;  // ready for the input's next measurement
  CheckpointInfo info;
};

// The checkpoint at `dir`. `options` (optional): the continued run's, which must equal the
// map's on every key that changes the result (loadMap). `input` (optional): the log or city the
// continued run reads, which must be the checkpoint's (the same file, however it is named).
// Throws common::InputError naming the folder or file for a missing, incomplete or corrupt
// checkpoint, or one of another input.
Checkpoint loadCheckpoint(const std::string& dir, const PipelineOptions* options = nullptr, const std::string& input = "");

// Reads past the first `n` measurements of `source` (named `name` in errors): InputError when it
// ends before them (not the input the checkpoint was made from).
void skipMeasurements(io::DataSource& source, std::uint64_t n, const std::string& name);

// Saves a checkpoint every `every_keyframes` keyframes of a run. The CPU and wall time it
// records count from its construction, on top of `earlier` (a continued run's checkpoint).
class Checkpointer {
 public:
  // `start_measurements`: the pipeline's measurements before its input's first (a resumed map's).
  Checkpointer(std::string dir, size_t every_keyframes, CheckpointInfo earlier, std::uint64_t start_measurements);
  // What the caller counts, read once global SLAM has caught up, saved with each checkpoint.
  void setCounters(std::function<std::map<std::string, double>()> counters) { counters_ = std::move(counters); }
  // After each step: saves when the map has gained `every_keyframes` since the last save.
  // Returns whether it saved.
  bool afterStep(Pipeline& pipeline, const io::DataSource& source);
  // Waits for global SLAM (a filter failure there reported against `source`), then saves.
  void save(Pipeline& pipeline, const io::DataSource& source);
  // The run's CPU and wall seconds so far, the earlier stretches included.
  double cpuSeconds() const;
  double wallSeconds() const;
  size_t saved() const { return saved_; }

 private:
  std::string dir_;
  size_t every_;
  CheckpointInfo earlier_;
  std::uint64_t start_measurements_;
  size_t last_keyframes_;
  double cpu0_;
  common::Stopwatch wall_;
  size_t saved_ = 0;
  std::function<std::map<std::string, double>()> counters_;
};

// Pipeline::runInput() with a checkpoint after each step that `saver` finds due: the rest of
// `source`, then global SLAM caught up (finish() is the caller's, after saving its outputs).
void runCheckpointed(Pipeline& pipeline, io::DataSource& source, Checkpointer& saver);

}  // namespace urbanslam::slam
