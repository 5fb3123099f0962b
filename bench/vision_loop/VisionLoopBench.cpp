// Speed of the Tree of Words pieces: descriptor → word (≤ k·L comparisons) on a full
// k = 10, L = 6 tree (10^6 words), query time against 10^3 … 10^6 images (synthetic bags: 300
// words per image drawn uniformly from 10^6 words), loading a 10^6-word vocabulary, and the
// whole per-frame time on 640×480 images (extraction, quantisation, query, verification).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "urbanslam/vision_loop/ImageDatabase.h"
#include "urbanslam/vision_loop/ImageSequence.h"
#include "urbanslam/vision_loop/LoopDetector.h"
#include "urbanslam/vision_loop/VocabularyFile.h"
#include <opencv2/imgproc.hpp>

using namespace urbanslam::vision_loop;

namespace {

// A complete k-ary tree of depth L with random centres (the shape of a trained tree; k-means on
// 10^7 descriptors is not what this measures).
Vocabulary syntheticVocabulary(DescriptorType type, uint32_t k, uint32_t levels, uint64_t seed) {
  VocabularyData d;
  d.type = type;
  d.branching = k;
  d.depth = levels;
  d.training_images = 1000;
  const int bytes = descriptorBytes(type);
  std::mt19937_64 rng(seed);
  size_t level_begin = 0, level_size = 1;
  d.first_child.push_back(0), d.child_count.push_back(0), d.word_of_node.push_back(VocabularyData::kNoWord);
  for (uint32_t l = 0; l < levels; ++l) {
    for (size_t n = level_begin; n < level_begin + level_size; ++n) {
      d.first_child[n] = static_cast<uint32_t>(d.first_child.size());
      d.child_count[n] = k;
      for (uint32_t c = 0; c < k; ++c)
        d.first_child.push_back(0), d.child_count.push_back(0), d.word_of_node.push_back(VocabularyData::kNoWord);
    }
    level_begin += level_size;
    level_size *= k;
  }
  d.centres.resize(d.first_child.size() * bytes);
  for (auto& b : d.centres) b = static_cast<uint8_t>(rng() % (type == DescriptorType::Sift ? 64 : 256));
  if (type == DescriptorType::Sift) {
    d.inverse_norms.resize(d.first_child.size());
    for (size_t i = 0; i < d.inverse_norms.size(); ++i) {
      double n2 = 0;
      for (int j = 0; j < bytes; ++j) n2 += double(d.centres[i * bytes + j]) * d.centres[i * bytes + j];
      d.inverse_norms[i] = n2 > 0 ? static_cast<float>(1 / std::sqrt(n2)) : 0.f;
    }
  }
  for (uint32_t n = 0; n < d.first_child.size(); ++n)
    if (d.child_count[n] == 0) d.word_of_node[n] = static_cast<uint32_t>(d.node_of_word.size()), d.node_of_word.push_back(n);
  d.idf.assign(d.node_of_word.size(), 1.f);
  return Vocabulary(std::move(d));
}

const Vocabulary& bigVocabulary(DescriptorType type) {
  static const Vocabulary sift = syntheticVocabulary(DescriptorType::Sift, 10, 6, 1);
  static const Vocabulary orb = syntheticVocabulary(DescriptorType::Orb, 10, 6, 2);
  return type == DescriptorType::Sift ? sift : orb;
}

void BM_Quantize(benchmark::State& state) {
  const auto type = static_cast<DescriptorType>(state.range(0));
  const Vocabulary& v = bigVocabulary(type);
  std::mt19937_64 rng(3);
  std::vector<uint8_t> d(1000 * v.descriptorBytes());
  for (auto& b : d) b = static_cast<uint8_t>(rng() % (type == DescriptorType::Sift ? 64 : 256));
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(v.quantize(d.data() + (i++ % 1000) * v.descriptorBytes()));
  }
  state.counters["words"] = static_cast<double>(v.wordCount());
  state.counters["comparisons"] = v.branching() * v.depth();  // one per child on the path
  state.SetLabel(descriptorName(type) + " k=10 L=6");
}
BENCHMARK(BM_Quantize)->Arg(int(DescriptorType::Sift))->Arg(int(DescriptorType::Orb));

BagOfWords randomBag(std::mt19937_64& rng, size_t words, int size) {
  std::vector<WordWeight> raw;
  std::uniform_real_distribution<float> w(0.1f, 1.f);
  for (int i = 0; i < size; ++i) raw.push_back({static_cast<WordId>(rng() % words), w(rng)});
  return makeBagOfWords(std::move(raw));
}

void BM_Query(benchmark::State& state) {
  const size_t images = static_cast<size_t>(state.range(0));
  const size_t words = static_cast<size_t>(state.range(1));
  std::mt19937_64 rng(4);
  ImageDatabase db(words);
  for (size_t i = 0; i < images; ++i) db.add(randomBag(rng, words, 300));
  std::vector<BagOfWords> queries;
  for (int i = 0; i < 64; ++i) queries.push_back(randomBag(rng, words, 300));
  QueryOptions o;
  o.max_results = 50;
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(db.query(queries[i++ % queries.size()], o));
  state.counters["images"] = static_cast<double>(images);
  state.counters["words"] = static_cast<double>(words);
  state.counters["postings"] = static_cast<double>(db.postingCount());
}
// {images, vocabulary words}: the size sweep with a 10^6-word vocabulary, and the shipped
// 10^4-word size for contrast (inverted files 100x longer: cost grows 100x faster with images).
BENCHMARK(BM_Query)
    ->Args({1000, 1000000})
    ->Args({10000, 1000000})
    ->Args({100000, 1000000})
    ->Args({1000000, 1000000})
    ->Args({1000, 10000})
    ->Args({10000, 10000})
    ->Args({100000, 10000})
    ->Unit(benchmark::kMillisecond);

void BM_LoadVocabulary(benchmark::State& state) {
  const auto type = static_cast<DescriptorType>(state.range(0));
  const auto path = (std::filesystem::temp_directory_path() / ("urbanslam_bench_" + descriptorName(type) + "_k10_L6.usvoc")).string();
  saveVocabulary(bigVocabulary(type), path);
  for (auto _ : state) benchmark::DoNotOptimize(loadVocabulary(path).wordCount());
  state.counters["MB"] = std::filesystem::file_size(path) / 1e6;
  state.SetLabel(descriptorName(type) + " 10^6 words");
  std::filesystem::remove(path);
}
BENCHMARK(BM_LoadVocabulary)->Arg(int(DescriptorType::Sift))->Arg(int(DescriptorType::Orb))->Unit(benchmark::kMillisecond);

// Shipped test sequence, upscaled to 640×480 (the size the time budget refers to).
const std::vector<cv::Mat>& frames640() {
  static const std::vector<cv::Mat> frames = [] {
    std::vector<cv::Mat> out;
    auto seq = openImageSequence(std::string(URBANSLAM_SOURCE_DIR) + "/rawlogs/rtabmap-loop-excerpt");
    NamedImage img;
    while (seq->next(img)) {
      cv::Mat m;
      cv::resize(img.gray, m, cv::Size(640, 480), 0, 0, cv::INTER_LINEAR);
      out.push_back(m);
    }
    return out;
  }();
  return frames;
}

void BM_Extract(benchmark::State& state) {
  FeatureOptions fo;
  fo.type = static_cast<DescriptorType>(state.range(0));
  FeatureExtractor ex(fo);
  const auto& frames = frames640();
  size_t i = 0, features = 0;
  for (auto _ : state) features += ex.extract(frames[i++ % frames.size()]).size();
  state.counters["features"] = benchmark::Counter(static_cast<double>(features), benchmark::Counter::kAvgIterations);
  state.SetLabel(descriptorName(fo.type) + " 640x480");
}
BENCHMARK(BM_Extract)->Arg(int(DescriptorType::Sift))->Arg(int(DescriptorType::Orb))->Unit(benchmark::kMillisecond);

// Whole per-frame time with the shipped default vocabulary: extraction, quantisation, query,
// verification, database insertion; the sequence is replayed so loops occur.
void BM_Frame(benchmark::State& state) {
  const auto type = static_cast<DescriptorType>(state.range(0));
  const std::string path =
      std::string(URBANSLAM_SOURCE_DIR) + "/share/vision_loop/" + (type == DescriptorType::Sift ? "sift_k10_L4.usvoc" : "orb_k10_L4.usvoc");
  auto vocabulary = std::make_shared<const Vocabulary>(loadVocabulary(path));
  FeatureOptions fo;
  fo.type = type;
  LoopDetector detector(vocabulary, fo);
  const auto& frames = frames640();
  size_t i = 0, detections = 0;
  double extraction = 0, quantization = 0, query = 0, verification = 0;
  for (auto _ : state) {
    detections += detector.process(frames[i++ % frames.size()]).detected() ? 1 : 0;
    const auto& t = detector.lastTimings();
    extraction += t.extraction_ms, quantization += t.quantization_ms, query += t.query_ms, verification += t.verification_ms;
  }
  using C = benchmark::Counter;
  state.counters["extract_ms"] = C(extraction, C::kAvgIterations);
  state.counters["quantize_ms"] = C(quantization, C::kAvgIterations);
  state.counters["query_ms"] = C(query, C::kAvgIterations);
  state.counters["verify_ms"] = C(verification, C::kAvgIterations);
  state.counters["detections"] = static_cast<double>(detections);
  state.SetLabel(descriptorName(type) + " 640x480, default vocabulary");
}
BENCHMARK(BM_Frame)->Arg(int(DescriptorType::Sift))->Arg(int(DescriptorType::Orb))->Unit(benchmark::kMillisecond)->Iterations(200);

}  // namespace

BENCHMARK_MAIN();
