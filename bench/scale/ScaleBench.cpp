// scale_bench (--city CITY_INI | --log LOG) [--ini PIPELINE_INI] --out DIR [--progress-every N]
// Runs the SLAM pipeline on a simulated city streamed from the simulator (no file) or on a log,
// records every step's time with the map's size at that step, and writes DIR/steps.csv
// (keyframes, step_ms, wall_s), DIR/step_time.png (p50 / p99 / max of the step time per bin of
// map size), DIR/corrections.csv and DIR/global_latency.png (each full correction's latency
// against the keyframe whose closure it brought in), the run's usual outputs (the front end's and global SLAM's figures in stats.json),
// the CPU time of the mapping (both threads) (so `urbanslam eval DIR --truth SIM_DIR` scores it) and
// one JSON summary on stdout. While it runs, DIR.progress.csv (beside DIR, which is replaced as a
// whole when the outputs are written) gains a row every N keyframes (10000 unless told;
// ProgressLog.h), so a run stopped early still tells how its cost grew; at the end it moves to
// DIR/progress.csv.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Heap.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/laser_loop/LinePlot.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/Pipeline.h"
#include "urbanslam/slam/PipelineOptions.h"
#include "urbanslam/slam/RunOutputs.h"
#include "ProgressLog.h"

using namespace urbanslam;

namespace {

struct StepRecorder : slam::PipelineObserver {
  std::vector<size_t> keyframes;
  std::vector<double> step_ms;
  void onStep(const slam::StepEvent& e) override {
    keyframes.push_back(e.keyframes);
    step_ms.push_back(e.step_ms);
  }
  // From global SLAM's thread; read after the run.
  std::vector<size_t> corrected_keyframe;
  std::vector<double> latency_ms;
  void onPosesUpdated(const slam::PosesUpdatedEvent& e) override {
    if (e.keyframe == static_cast<size_t>(-1)) return;
    corrected_keyframe.push_back(e.keyframe);
    latency_ms.push_back(e.latency_ms);
  }
};

}  // namespace

constexpr const char* kUsage = "usage: scale_bench (--city CITY_INI | --log LOG) [--ini PIPELINE_INI] --out DIR [--progress-every N]\n";

int main(int argc, char** argv) {
  urbanslam::common::keepFreedBuffers();  // as the urbanslam command does
  std::string city, log, ini = std::string(URBANSLAM_SOURCE_DIR) + "/ini/default.ini", out;
  long progress_every = 10000;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::cout << kUsage << "The pipeline on a simulated city streamed from the simulator, or on a log; prints one JSON line.\n";
      return 0;
    }
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--city")
      city = argv[i + 1];
    else if (a == "--log")
      log = argv[i + 1];
    else if (a == "--ini")
      ini = argv[i + 1];
    else if (a == "--out")
      out = argv[i + 1];
    else if (a == "--progress-every")
      progress_every = std::atol(argv[i + 1]);
  }
  if (out.empty() || city.empty() == log.empty() || progress_every <= 0) {
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
    const std::string progress_path = out + ".progress.csv";
    StepRecorder rec;  // outlives the pipeline, whose global SLAM thread calls it
    bench::ProgressLog progress(progress_path, static_cast<size_t>(progress_every));
    slam::Pipeline pipeline(options);
    pipeline.addObserver(&rec);
    pipeline.addObserver(&progress);
    const double cpu0 = bench::processCpuSeconds();
    pipeline.run(*source);
    const double cpu_s = bench::processCpuSeconds() - cpu0;
    const common::Json stats =
        slam::writeRunOutputs(pipeline, out, {city.empty() ? log : city, source->format(), ini, resolved, {}, {}, {}});
    std::filesystem::rename(progress_path, out + "/progress.csv");

    std::ofstream csv(out + "/steps.csv");
    csv << "keyframes,step_ms\n";
    for (size_t i = 0; i < rec.step_ms.size(); ++i) csv << rec.keyframes[i] << "," << rec.step_ms[i] << "\n";
    // Step time per bin of map size: 40 bins over the run.
    const size_t n = rec.keyframes.empty() ? 0 : rec.keyframes.back();
    const size_t bins = 40, width = std::max<size_t>(1, (n + bins - 1) / bins);
    laser_loop::PlotSeries p50{"p50", {}, {}, 0x2060e0}, p99{"p99", {}, {}, 0x2020c0}, mx{"max", {}, {}, 0x808080};
    std::vector<std::vector<double>> per(bins + 1);
    for (size_t i = 0; i < rec.step_ms.size(); ++i) per[std::min(bins, rec.keyframes[i] / width)].push_back(rec.step_ms[i]);
    for (size_t b = 0; b <= bins; ++b) {
      if (per[b].empty()) continue;
      const double x = static_cast<double>((b + 0.5) * width);
      p50.x.push_back(x), p50.y.push_back(common::percentile(per[b], 50));
      p99.x.push_back(x), p99.y.push_back(common::percentile(per[b], 99));
      mx.x.push_back(x), mx.y.push_back(common::percentile(per[b], 100));
    }
    laser_loop::writePlotPng(out + "/step_time.png", {{"step time against map size", "keyframes", "ms", {p50, p99, mx}}});
    // Global SLAM: each full correction, by the keyframe whose closure it brought in.
    std::ofstream lat(out + "/corrections.csv");
    lat << "keyframe,latency_ms\n";
    laser_loop::PlotSeries latency{"closure -> corrected map", {}, {}, 0xc02020};
    for (size_t i = 0; i < rec.latency_ms.size(); ++i) {
      lat << rec.corrected_keyframe[i] << "," << rec.latency_ms[i] << "\n";
      latency.x.push_back(static_cast<double>(rec.corrected_keyframe[i]));
      latency.y.push_back(rec.latency_ms[i] / 1e3);
    }
    if (!latency.x.empty())
      laser_loop::writePlotPng(out + "/global_latency.png", {{"global SLAM latency against map size", "keyframes", "s", {latency}}});
    common::Json j = common::Json::object();
    j["input"] = city.empty() ? log : city;
    j["keyframes"] = n;
    j["timing"] = stats.at("timing");
    j["counts"] = stats.at("counts");
    // Front end and global SLAM run on two threads: the real-time factor on one core is the log's
    // duration over the CPU time of both.
    const double duration = pipeline.stats().last_timestamp - pipeline.stats().first_timestamp;
    j["cpu_s"] = cpu_s;
    j["real_time_factor_one_core"] = cpu_s > 0 ? duration / cpu_s : 0.0;
    std::cout << j.dump() << "\n";
  } catch (const common::InputError& e) {
    std::cerr << "scale_bench: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
