// scale_bench (--city CITY_INI | --log LOG) [--ini PIPELINE_INI] --out DIR [--progress-every N]
//             [--checkpoint-every N [--continue]]
// Runs the SLAM pipeline on a simulated city streamed from the simulator (no file) or on a log,
// records every step's time with the map's size at that step, and writes DIR/steps.csv
// (keyframes, step_ms), DIR/step_time.png (p50 / p99 / max of the step time per bin of
// map size), DIR/corrections.csv and DIR/global_latency.png (each full correction's latency
// against the keyframe whose closure it brought in), the run's usual outputs (the front end's and global SLAM's figures in stats.json),
// the CPU time of the mapping (both threads) (so `urbanslam eval DIR --truth SIM_DIR` scores it) and
// one JSON summary on stdout. While it runs, DIR.progress.csv (beside DIR, which is replaced as a
// whole when the outputs are written) gains a row every N keyframes (10000 unless told;
// ProgressLog.h), so a run stopped early still tells how its cost grew; at the end it moves to
// DIR/progress.csv, as DIR.steps.csv and DIR.corrections.csv, written as the run goes, do.
//
// A run too long for one sitting saves itself every N keyframes with --checkpoint-every
// (DIR.checkpoint/, slam/Checkpoint.h); the same command with --continue goes on from the last
// checkpoint, with the same map as an uninterrupted run and the CSV files' times and counts
// going on from the checkpoint's (loading it is not counted).

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Heap.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/laser_loop/LinePlot.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/Checkpoint.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/RunOutputs.h"
#include "ProgressLog.h"

using namespace urbanslam;

namespace {

// Every step's time and every full correction's latency, appended to two CSV files as the run
// goes (a run of 10^6 keyframes never holds them), each continuing after `earlier` rows.
struct StepRecorder : slam::PipelineObserver {
  static constexpr const char* kStepsHeader = "keyframes,step_ms";
  static constexpr const char* kCorrectionsHeader = "keyframe,latency_ms";
  StepRecorder(const std::string& steps_path, const std::string& corrections_path, size_t earlier_steps, size_t earlier_corrections)
      : steps_rows(earlier_steps), correction_rows(earlier_corrections) {
    bench::keepCsvRows(steps_path, earlier_steps, kStepsHeader);
    bench::keepCsvRows(corrections_path, earlier_corrections, kCorrectionsHeader);
    steps.open(steps_path, std::ios::app);
    corrections.open(corrections_path, std::ios::app);
  }
  void onStep(const slam::StepEvent& e) override {
    steps << e.keyframes << "," << e.step_ms << "\n";
    ++steps_rows;
  }
  // From global SLAM's thread.
  void onPosesUpdated(const slam::PosesUpdatedEvent& e) override {
    if (e.keyframe == static_cast<size_t>(-1)) return;
    corrections << e.keyframe << "," << e.latency_ms << "\n";
    ++correction_rows;
  }
  // Before a checkpoint records the row counts (global SLAM idle).
  void flush() {
    steps.flush();
    corrections.flush();
  }
  std::ofstream steps, corrections;
  std::atomic<size_t> steps_rows, correction_rows;
};

// Two numeric columns of a CSV file written above.
void readColumns(const std::string& path, std::vector<double>& a, std::vector<double>& b) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  double x = 0, y = 0;
  char comma = 0;
  while (in >> x >> comma >> y) a.push_back(x), b.push_back(y);
}

}  // namespace

constexpr const char* kUsage =
    "usage: scale_bench (--city CITY_INI | --log LOG) [--ini PIPELINE_INI] --out DIR [--progress-every N] [--checkpoint-every N "
    "[--continue]]\n";

int main(int argc, char** argv) {
  urbanslam::common::keepFreedBuffers();  // as the urbanslam command does
  std::string city, log, ini = std::string(URBANSLAM_SOURCE_DIR) + "/ini/default.ini", out;
  long progress_every = 10000, checkpoint_every = 0;
  bool continuing = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::cout << kUsage
                << "The pipeline on a simulated city streamed from the simulator, or on a log; prints one JSON line.\n"
                   "--checkpoint-every N saves the run every N keyframes to DIR.checkpoint/; --continue goes on from there.\n";
      return 0;
    }
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--continue") {
      continuing = true;
      continue;
    }
    if (i + 1 >= argc) {
      std::cerr << kUsage;
      return 2;
    }
    ++i;
    if (a == "--city")
      city = argv[i];
    else if (a == "--log")
      log = argv[i];
    else if (a == "--ini")
      ini = argv[i];
    else if (a == "--out")
      out = argv[i];
    else if (a == "--progress-every")
      progress_every = std::atol(argv[i]);
    else if (a == "--checkpoint-every")
      checkpoint_every = std::atol(argv[i]);
    else {
      std::cerr << "scale_bench: unknown option " << a << "\n" << kUsage;
      return 2;
    }
  }
  if (out.empty() || city.empty() == log.empty() || progress_every <= 0 || checkpoint_every < 0) {
    std::cerr << kUsage;
    return 2;
  }
  try {
    std::string resolved;
    slam::PipelineOptions options = slam::loadPipelineOptions(ini, &resolved);
    slam::resolveDefaultPaths(options, URBANSLAM_SOURCE_DIR);
    std::unique_ptr<io::DataSource> source =
        city.empty() ? io::openDataSource(log) : std::make_unique<sim::SimulatedSource>(sim::loadSimOptions(city));
    while (out.size() > 1 && out.back() == '/') out.pop_back();
    const std::string input = std::filesystem::absolute(city.empty() ? log : city).string();
    const std::string checkpoint_dir = slam::checkpointPath(out);
    // The observers outlive the pipeline, whose global SLAM thread calls them.
    std::optional<StepRecorder> rec;
    std::optional<bench::ProgressLog> progress;
    std::unique_ptr<slam::Pipeline> pipeline;
    slam::CheckpointInfo earlier;
    if (continuing) {
      slam::Checkpoint c = slam::loadCheckpoint(checkpoint_dir, &options, input);
      std::cerr << "scale_bench: continuing from " << checkpoint_dir << " at " << c.info.keyframes << " keyframes\n";
      slam::skipMeasurements(*source, c.info.input_measurements, input);
      pipeline = std::move(c.pipeline);
      earlier = c.info;
    } else {
      pipeline = std::make_unique<slam::Pipeline>(options);
      earlier.input = input;
    }
    const auto counter = [&](const char* key) {
      const auto it = earlier.counters.find(key);
      return it == earlier.counters.end() ? size_t{0} : static_cast<size_t>(it->second);
    };
    rec.emplace(out + ".steps.csv", out + ".corrections.csv", counter("step_rows"), counter("correction_rows"));
    progress.emplace(out + ".progress.csv", static_cast<size_t>(progress_every), earlier);
    pipeline->addObserver(&*rec);
    pipeline->addObserver(&*progress);
    slam::Checkpointer saver(checkpoint_dir, static_cast<size_t>(checkpoint_every), earlier, 0);
    saver.setCounters([&] {
      rec->flush();
      auto c = progress->totals();
      c["step_rows"] = static_cast<double>(rec->steps_rows.load());
      c["correction_rows"] = static_cast<double>(rec->correction_rows.load());
      return c;
    });
    slam::runCheckpointed(*pipeline, *source, saver);
    pipeline->finish(*source);
    const double cpu_s = saver.cpuSeconds();
    const common::Json stats =
        slam::writeRunOutputs(*pipeline, out, {city.empty() ? log : city, source->format(), ini, resolved, {}, {}, {}});
    rec->flush();
    for (const char* name : {"progress.csv", "steps.csv", "corrections.csv"})
      std::filesystem::rename(out + "." + name, out + "/" + name);
    std::error_code ec;
    std::filesystem::remove_all(checkpoint_dir, ec);

    // Step time per bin of map size: 40 bins over the run.
    std::vector<double> step_keyframes, step_ms;
    readColumns(out + "/steps.csv", step_keyframes, step_ms);
    const size_t n = step_keyframes.empty() ? 0 : static_cast<size_t>(step_keyframes.back());
    const size_t bins = 40, width = std::max<size_t>(1, (n + bins - 1) / bins);
    laser_loop::PlotSeries p50{"p50", {}, {}, 0x2060e0}, p99{"p99", {}, {}, 0x2020c0}, mx{"max", {}, {}, 0x808080};
    std::vector<std::vector<double>> per(bins + 1);
    for (size_t i = 0; i < step_ms.size(); ++i) per[std::min(bins, static_cast<size_t>(step_keyframes[i]) / width)].push_back(step_ms[i]);
    for (size_t b = 0; b <= bins; ++b) {
      if (per[b].empty()) continue;
      const double x = static_cast<double>((b + 0.5) * width);
      p50.x.push_back(x), p50.y.push_back(common::percentile(per[b], 50));
      p99.x.push_back(x), p99.y.push_back(common::percentile(per[b], 99));
      mx.x.push_back(x), mx.y.push_back(common::percentile(per[b], 100));
    }
    laser_loop::writePlotPng(out + "/step_time.png", {{"step time against map size", "keyframes", "ms", {p50, p99, mx}}});
    // Global SLAM: each full correction, by the keyframe whose closure it brought in.
    laser_loop::PlotSeries latency{"closure -> corrected map", {}, {}, 0xc02020};
    readColumns(out + "/corrections.csv", latency.x, latency.y);
    for (double& y : latency.y) y /= 1e3;
    if (!latency.x.empty())
      laser_loop::writePlotPng(out + "/global_latency.png", {{"global SLAM latency against map size", "keyframes", "s", {latency}}});
    common::Json j = common::Json::object();
    j["input"] = city.empty() ? log : city;
    j["keyframes"] = n;
    j["timing"] = stats.at("timing");
    j["counts"] = stats.at("counts");
    // Front end and global SLAM run on two threads: the real-time factor on one core is the log's
    // duration over the CPU time of both.
    const double duration = pipeline->stats().last_timestamp - pipeline->stats().first_timestamp;
    j["cpu_s"] = cpu_s;
    j["real_time_factor_one_core"] = cpu_s > 0 ? duration / cpu_s : 0.0;
    std::cout << j.dump() << "\n";
  } catch (const common::InputError& e) {
    std::cerr << "scale_bench: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
