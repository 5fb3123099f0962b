// local_bench (--city CITY_INI | --log LOG) [--ini PIPELINE_INI] [--scans N] [--repeat R]
// Local SLAM alone (slam::LocalTrajectory: motion, keyframes, the submap match of every scan),
// replayed R times over the first N scans of a simulated city or a log held in memory, on this
// one thread: the CPU time of each replay, median and spread, as one JSON line. Deterministic
// work with no second thread and no input or output in the timed part, so a change to local
// SLAM's matching is measured to a few per cent, where a whole run varies by ten (global SLAM's
// share and the machine's). `check` sums every keyframe step's x, y and heading: equal across
// builds when the change leaves the matches as they were.
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string>
#include <variant>
#include <vector>

#include "urbanslam/common/Error.h"
#include "urbanslam/common/Heap.h"
#include "urbanslam/common/Json.h"
#include "urbanslam/common/Timing.h"
#include "urbanslam/io/DataSource.h"
#include "urbanslam/sim/SimOptions.h"
#include "urbanslam/sim/SimulatedSource.h"
#include "urbanslam/slam/LocalTrajectory.h"
#include "urbanslam/slam/PipelineOptions.h"

using namespace urbanslam;
using common::threadCpuSeconds;

int main(int argc, char** argv) {
  urbanslam::common::keepFreedBuffers();  // as the urbanslam command does
  const char* usage = "usage: local_bench (--city CITY_INI | --log LOG) [--ini PIPELINE_INI] [--scans N] [--repeat R]\n";
  if (argc > 1 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::cout << usage;
    return 0;
  }
  std::string city, log, ini = std::string(URBANSLAM_SOURCE_DIR) + "/ini/default.ini";
  size_t scans = 1000;
  int repeat = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--city")
      city = v;
    else if (a == "--log")
      log = v;
    else if (a == "--ini")
      ini = v;
    else if (a == "--scans" || a == "--repeat") {
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end || n < 1) {
        std::cerr << "local_bench: " << a << " wants a positive whole number, not '" << v << "'\n";
        return 2;
      }
      if (a == "--scans")
        scans = static_cast<size_t>(n);
      else
        repeat = static_cast<int>(std::min<long>(n, 1000));
    } else {
      std::cerr << "local_bench: unknown option '" << a << "'\n" << usage;
      return 2;
    }
  }
  if (argc % 2 == 0) {
    std::cerr << "local_bench: '" << argv[argc - 1] << "' has no value\n" << usage;
    return 2;
  }
  if (city.empty() == log.empty()) {
    std::cerr << usage;
    return 2;
  }
  try {
    const slam::PipelineOptions options = slam::loadPipelineOptions(ini);
    std::unique_ptr<io::DataSource> source =
        city.empty() ? io::openDataSource(log) : std::make_unique<sim::SimulatedSource>(sim::loadSimOptions(city));
    std::vector<io::Measurement> log_in_memory;
    io::Measurement m;
    size_t taken = 0;
    while (taken < scans && source->next(m)) {
      taken += std::holds_alternative<io::LaserScan>(m) ? 1 : 0;
      log_in_memory.push_back(std::move(m));
    }
    std::vector<double> cpu_s;
    size_t keyframes = 0;
    double check[3] = {0, 0, 0};
    for (int r = 0; r < repeat; ++r) {
      slam::LocalTrajectory local(options);
      const double t0 = threadCpuSeconds();
      for (const io::Measurement& x : log_in_memory) local.add(x);
      cpu_s.push_back(threadCpuSeconds() - t0);
      keyframes = local.keyframes().size();
      check[0] = check[1] = check[2] = 0;
      for (const auto& k : local.keyframes()) check[0] += k.z.x, check[1] += k.z.y, check[2] += k.z.phi;
    }
    std::sort(cpu_s.begin(), cpu_s.end());
    const double median = cpu_s[cpu_s.size() / 2];
    common::Json j = common::Json::object();
    j["scans"] = taken;
    j["keyframes"] = keyframes;
    j["repeat"] = repeat;
    j["cpu_s_median"] = median;
    j["cpu_s_min"] = cpu_s.front();
    j["cpu_s_max"] = cpu_s.back();
    j["ms_per_scan"] = taken ? 1e3 * median / static_cast<double>(taken) : 0.0;
    j["check"] = common::Json::arrayOf(std::vector<double>{check[0], check[1], check[2]});
    std::cout << j.dump() << "\n";
    return 0;
  } catch (const common::InputError& e) {
    std::cerr << "local_bench: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "local_bench: " << e.what() << "\n";
    return 1;
  }
}
