// Speed targets of the issue: features of a 361-beam scan < 20 µs, one pair < 100 ns, screening
// 10^6 stored keyframes < 20 ms. Real scans: Victoria Park excerpt (361 beams, shipped in the
// repo); the shipped default model (its T stumps) when present, else a 50-stump model fitted here.
// Environment: LASER_LOOP_MODEL, a model path relative to the repository.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <fstream>
#include <random>

#include "urbanslam/io/DataSource.h"
#include "urbanslam/laser_loop/AdaBoost.h"
#include "urbanslam/laser_loop/LoopDetector.h"

using namespace urbanslam;
using namespace urbanslam::laser_loop;

namespace {

const std::vector<io::LaserScan>& scans() {
  static const std::vector<io::LaserScan> s = [] {
    std::vector<io::LaserScan> out;
    auto src = io::openDataSource(std::string(URBANSLAM_SOURCE_DIR) + "/rawlogs/victoria-park-excerpt");
    io::Measurement m;
    while (src->next(m))
      if (auto* l = std::get_if<io::LaserScan>(&m)) out.push_back(*l);
    return out;
  }();
  return s;
}

const ClassifierModel& model() {
  static const ClassifierModel m = [] {
    // LASER_LOOP_MODEL=share/laser_loop/default-360.model measures another shipped model.
    const char* chosen = std::getenv("LASER_LOOP_MODEL");
    const std::string path = std::string(URBANSLAM_SOURCE_DIR) + "/" + (chosen ? chosen : "share/laser_loop/default.model");
    if (std::ifstream(path)) return loadModel(path);
    // Fallback: boost 50 rounds on pairs of the excerpt's scans labelled by index distance.
    ClassifierModel fm;
    std::vector<FeatureVector> f;
    for (const auto& s : scans()) f.push_back(computeFeatures(s, fm.params));
    PairTable t;
    for (size_t i = 0; i + 20 < f.size(); ++i) {
      t.add(f[i], f[i + 1], true);
      t.add(f[i], f[i + 20], false);
    }
    fm.classifier = trainAdaBoost(t, {}, 50);
    return fm;
  }();
  return m;
}

void BM_Features361(benchmark::State& st) {
  const auto& s = scans();
  const FeatureParams p = model().params;
  size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(computeFeatures(s[i], p));
    if (++i == s.size()) i = 0;
  }
  st.SetLabel(std::to_string(s.front().size()) + " beams, decimated to the model's beam_increment_deg");
}
BENCHMARK(BM_Features361)->Unit(benchmark::kMicrosecond);

// The same scans with every beam kept (beam_increment_deg = 0): all 361 beams go through every
// feature, the "features of a 361-beam scan" without the 1° decimation of the default.
void BM_Features361AllBeams(benchmark::State& st) {
  const auto& s = scans();
  FeatureParams p = model().params;
  p.beam_increment_deg = 0;
  size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(computeFeatures(s[i], p));
    if (++i == s.size()) i = 0;
  }
  st.SetLabel(std::to_string(s.front().size()) + " beams, none decimated");
}
BENCHMARK(BM_Features361AllBeams)->Unit(benchmark::kMicrosecond);

void BM_PairScore(benchmark::State& st) {
  std::vector<FeatureVector> f;
  for (const auto& s : scans()) f.push_back(computeFeatures(s, model().params));
  const StrongClassifier& c = model().classifier;
  size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(c.score(f[i], f[(i + 7) % f.size()]));
    if (++i == f.size()) i = 0;
  }
  st.SetLabel(std::to_string(c.size()) + " stumps");
}
BENCHMARK(BM_PairScore)->Unit(benchmark::kNanosecond);

void BM_Screen(benchmark::State& st) {
  std::vector<FeatureVector> f;
  for (const auto& s : scans()) f.push_back(computeFeatures(s, model().params));
  LoopDetector det(model());
  const size_t n = static_cast<size_t>(st.range(0));
  det.reserve(n);
  std::mt19937 rng(1);
  std::normal_distribution<double> jitter(1.0, 0.05);
  for (size_t k = 0; k < n; ++k) {
    FeatureVector v = f[k % f.size()];
    for (auto& x : v) x *= jitter(rng);  // distinct keyframes around real feature values
    det.addKeyframe(v);
  }
  std::vector<float> scores;
  size_t q = 0;
  for (auto _ : st) {
    det.screen(f[q++ % f.size()], scores);
    benchmark::DoNotOptimize(scores.data());
  }
  st.SetLabel(std::to_string(model().classifier.size()) + " stumps");
}
BENCHMARK(BM_Screen)->Arg(1000000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
